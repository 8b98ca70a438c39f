//! Where each joint and link stands in the URDF text (urdf-rs keeps no positions), and the
//! nesting check that runs before any parser sees the text.

use std::collections::HashMap;

use crate::error::{Error, Result};

/// The deepest element nesting accepted in a URDF. A URDF needs about 5 levels (`robot`,
/// `link`, `inertial`, `inertia`); deeper documents are refused before parsing, so that no
/// parser recursion can overflow the stack.
pub const MAX_XML_DEPTH: usize = 64;

/// Lines of the URDF's joints and links, and which joints have a `<limit>`, from a light XML
/// pass (urdf-rs keeps no positions).
pub(super) struct LineIndex {
    pub(super) joints: HashMap<String, (u32, bool)>,
    pub(super) links: HashMap<String, u32>,
}

impl LineIndex {
    pub(super) fn new(text: &str) -> Self {
        let mut joints = HashMap::new();
        let mut links = HashMap::new();
        // byte offset of every line start, for a binary search per element (roxmltree's own
        // `text_pos_at` scans from the start: quadratic over a long file)
        let starts: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let line_of = |offset: usize| starts.partition_point(|&s| s <= offset) as u32;
        if let Ok(doc) = roxmltree::Document::parse(text) {
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

/// Refuses XML nested deeper than [`MAX_XML_DEPTH`], in one pass over the text that counts
/// opening and closing tags (comments, processing instructions, CDATA and declarations are
/// skipped; quoted attribute values may hold `>`).
pub(super) fn check_depth(text: &str, source: &str) -> Result<()> {
    let bytes = text.as_bytes();
    let (mut depth, mut line, mut i) = (0usize, 1u32, 0usize);
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
                    } else if j == 0 || bytes.get(j - 1) != Some(&b'/') {
                        depth += 1;
                        if depth > MAX_XML_DEPTH {
                            return Err(Error::UrdfSyntax {
                                source_name: source.to_string(),
                                message: format!(
                                    "line {line}: elements nested {depth} deep; at most {MAX_XML_DEPTH} levels are read"
                                ),
                            });
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
