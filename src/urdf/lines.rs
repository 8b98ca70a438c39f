//! Where each joint and link stands in the URDF text (urdf-rs keeps no positions), and the
//! nesting check that runs before any parser sees the text.

use std::collections::HashMap;

use crate::error::{Error, Result};

/// The deepest element nesting accepted in a URDF. A URDF needs about 5 levels (`robot`,
/// `link`, `inertial`, `inertia`); deeper documents are refused before parsing, so that no
/// parser recursion can overflow the stack.
pub const MAX_XML_DEPTH: usize = 64;

/// The most XML elements accepted in a URDF. A 7-joint arm's URDF has about 150, a humanoid's
/// with its visuals, collisions and Gazebo tags a few thousand; the parsers hold about 2 kB per
/// element, so a document of [`MAX_DOCUMENT_BYTES`](crate::limits::MAX_DOCUMENT_BYTES) in
/// small elements would take 18 GB. Refused before parsing, in the nesting check's pass.
pub const MAX_XML_ELEMENTS: usize = 200_000;

/// Lines of the URDF's joints and links, and which joints have a `<limit>`, from a light XML
/// pass (urdf-rs keeps no positions).
pub(super) struct LineIndex {
    pub(super) joints: HashMap<String, (u32, bool)>,
    pub(super) links: HashMap<String, u32>,
}

/// Byte offset of every line start, for a binary search per element (roxmltree's own
/// `text_pos_at` scans from the start: quadratic over a long file).
pub(super) struct Lines(Vec<usize>);

impl Lines {
    pub(super) fn new(text: &str) -> Self {
        Lines(
            std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        )
    }

    /// The 1-based line of byte `offset`.
    pub(super) fn of(&self, offset: usize) -> u32 {
        self.0.partition_point(|&s| s <= offset) as u32
    }
}

/// Parses the text as XML (errors with line and column), checks that its root is `<robot>`,
/// and that every attribute URDF reads as numbers holds numbers, naming the line, element,
/// attribute and value: urdf-rs reports such problems without saying where.
pub(super) fn parse_xml<'a>(text: &'a str, source: &str) -> Result<roxmltree::Document<'a>> {
    let syntax = |message: String| Error::UrdfSyntax {
        source_name: source.to_string(),
        message,
    };
    let doc = roxmltree::Document::parse(text).map_err(|e| syntax(format!("XML: {e}")))?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(syntax(format!(
            "the document's root element is <{}>, expected <robot>",
            root.tag_name().name()
        )));
    }
    const NUMERIC: &[&str] = &[
        "xyz",
        "rpy",
        "value",
        "ixx",
        "ixy",
        "ixz",
        "iyy",
        "iyz",
        "izz",
        "lower",
        "upper",
        "effort",
        "velocity",
        "acceleration",
        "damping",
        "friction",
        "multiplier",
        "offset",
    ];
    let lines = Lines::new(text);
    for node in doc.descendants().filter(|n| n.is_element()) {
        if !matches!(
            node.tag_name().name(),
            "origin" | "axis" | "mass" | "inertia" | "limit" | "dynamics" | "mimic"
        ) {
            continue;
        }
        for attr in node.attributes().filter(|a| NUMERIC.contains(&a.name())) {
            let bad = attr
                .value()
                .split_whitespace()
                .find(|token| token.parse::<f64>().is_err());
            if let Some(token) = bad {
                return Err(syntax(format!(
                    "line {}: <{} {}=\"{}\">: '{token}' is not a number",
                    lines.of(node.range().start),
                    node.tag_name().name(),
                    attr.name(),
                    attr.value()
                )));
            }
        }
    }
    Ok(doc)
}

impl LineIndex {
    pub(super) fn new(text: &str, doc: &roxmltree::Document<'_>) -> Self {
        let mut joints = HashMap::new();
        let mut links = HashMap::new();
        let lines = Lines::new(text);
        let line_of = |offset: usize| lines.of(offset);
        {
            for node in doc.root_element().children().filter(|n| n.is_element()) {
                let Some(name) = node.attribute("name") else {
                    continue;
                };
                let line = line_of(node.range().start);
                match node.tag_name().name() {
                    "joint" => {
                        let has_limit = node.children().any(|c| c.has_tag_name("limit"));
                        joints.entry(name.to_string()).or_insert((line, has_limit));
                    }
                    "link" => {
                        links.entry(name.to_string()).or_insert(line);
                    }
                    _ => {}
                }
            }
        }
        Self { joints, links }
    }
}

/// Refuses XML nested deeper than [`MAX_XML_DEPTH`] or with more than [`MAX_XML_ELEMENTS`]
/// elements, in one pass over the text that counts opening and closing tags (comments, processing instructions, CDATA and declarations are
/// skipped; quoted attribute values may hold `>`).
pub(super) fn check_depth(text: &str, source: &str) -> Result<()> {
    let bytes = text.as_bytes();
    let (mut depth, mut line, mut i, mut elements) = (0usize, 1u32, 0usize, 0usize);
    let refuse = |message: String| {
        Err(Error::UrdfSyntax {
            source_name: source.to_string(),
            message,
        })
    };
    let skip_to = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(bytes.len(), |k| from + k + end.len())
    };
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => {
                line += 1;
                i += 1;
            }
            b'<' => {
                let rest = &text[i..];
                let end = if rest.starts_with("<!--") {
                    skip_to(i, "-->")
                } else if rest.starts_with("<![CDATA[") {
                    skip_to(i, "]]>")
                } else if rest.starts_with("<?") {
                    skip_to(i, "?>")
                } else if rest.starts_with("<!") {
                    skip_to(i, ">")
                } else {
                    // a tag: find its end outside quotes
                    let (mut j, mut quote) = (i + 1, None);
                    while j < bytes.len() {
                        match (bytes[j], quote) {
                            (b'"' | b'\'', None) => quote = Some(bytes[j]),
                            (c, Some(q)) if c == q => quote = None,
                            (b'>', None) => break,
                            _ => {}
                        }
                        j += 1;
                    }
                    if rest.starts_with("</") {
                        depth = depth.saturating_sub(1);
                    } else {
                        elements += 1;
                        if elements > MAX_XML_ELEMENTS {
                            return refuse(format!(
                                "line {line}: more than {MAX_XML_ELEMENTS} elements; a robot's URDF has a few thousand at most (docs/limits.md)"
                            ));
                        }
                        if j == 0 || bytes.get(j - 1) != Some(&b'/') {
                            depth += 1;
                            if depth > MAX_XML_DEPTH {
                                return refuse(format!(
                                    "line {line}: elements nested {depth} deep; at most {MAX_XML_DEPTH} levels are read"
                                ));
                            }
                        }
                    }
                    j + 1
                };
                line += text[i..end.min(bytes.len())].matches('\n').count() as u32;
                i = end;
            }
            _ => i += 1,
        }
    }
    Ok(())
}
