//! The edits of a URDF's text that [`super::write`] makes: each element found by name,
//! replaced, added or removed in place with its line's indentation, every other byte of the
//! file kept.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::ops::Range;

use crate::model::payload::Payload;
use crate::model::Model;
use crate::spatial::Inertia;

/// One replacement of the source text.
pub(super) struct Edit {
    pub(super) range: Range<usize>,
    pub(super) text: String,
}

/// A number as it reads back exactly: plain where that is short, in exponent form otherwise.
pub(crate) fn number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// The `<link>` and `<joint>` elements of the robot, by name.
pub(super) struct Elements<'a, 'input> {
    pub(super) links: HashMap<&'a str, roxmltree::Node<'a, 'input>>,
    pub(super) joints: HashMap<&'a str, roxmltree::Node<'a, 'input>>,
}

impl<'a, 'input> Elements<'a, 'input> {
    pub(super) fn of(doc: &'a roxmltree::Document<'input>) -> Self {
        let mut links = HashMap::new();
        let mut joints = HashMap::new();
        for node in doc.root_element().children().filter(|n| n.is_element()) {
            let Some(name) = node.attribute("name") else {
                continue;
            };
            match node.tag_name().name() {
                "link" => links.entry(name).or_insert(node),
                "joint" => joints.entry(name).or_insert(node),
                _ => continue,
            };
        }
        Self { links, joints }
    }

    pub(super) fn link(
        &self,
        name: &str,
    ) -> std::result::Result<roxmltree::Node<'a, 'input>, String> {
        self.links
            .get(name)
            .copied()
            .ok_or_else(|| "no <link> of this name in the file".into())
    }

    pub(super) fn joint(
        &self,
        name: &str,
    ) -> std::result::Result<roxmltree::Node<'a, 'input>, String> {
        self.joints
            .get(name)
            .copied()
            .ok_or_else(|| "no <joint> of this name in the file".into())
    }
}

/// The one child element `name` of `node`, if any; two are refused (readers differ on which
/// counts).
pub(super) fn child<'a, 'input>(
    node: roxmltree::Node<'a, 'input>,
    name: &str,
) -> std::result::Result<Option<roxmltree::Node<'a, 'input>>, String> {
    let mut found = node
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == name);
    let first = found.next();
    if found.next().is_some() {
        return Err(format!(
            "it holds more than one <{name}>; readers differ on which counts"
        ));
    }
    Ok(first)
}

/// The whitespace that opens the line `offset` stands on (empty where other text precedes it).
pub(super) fn indent_at(text: &str, offset: usize) -> &str {
    let start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[start..offset];
    if before.chars().all(|c| c == ' ' || c == '\t') {
        before
    } else {
        ""
    }
}

/// Where the start tag of `node` ends: the offset of its `>` (quotes skipped), and whether it
/// closes the element (`/>`).
pub(super) fn start_tag_end(text: &str, node: roxmltree::Node<'_, '_>) -> (usize, bool) {
    let range = node.range();
    let mut quote = None;
    for (i, c) in text[range.clone()].char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '>') => {
                let at = range.start + i;
                return (at, text[..at].ends_with('/'));
            }
            _ => {}
        }
    }
    (range.end - 1, text[..range.end].ends_with("/>"))
}

/// An `<inertial>` element holding `inertia` (in the link's frame), indented by `indent`.
pub(super) fn inertial_element(inertia: &Inertia, indent: &str) -> String {
    let (c, i) = (&inertia.com, &inertia.inertia_com);
    format!(
        "<inertial>\n{indent}  <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/>\n{indent}  <mass value=\"{}\"/>\n{indent}  <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n{indent}</inertial>",
        number(c.x),
        number(c.y),
        number(c.z),
        number(inertia.mass),
        number(i[(0, 0)]),
        number(i[(0, 1)]),
        number(i[(0, 2)]),
        number(i[(1, 1)]),
        number(i[(1, 2)]),
        number(i[(2, 2)])
    )
}

/// The edit that gives link element `link` the inertial `inertia`: its `<inertial>`
/// replaced, or one added.
pub(super) fn set_inertial(
    text: &str,
    link: roxmltree::Node<'_, '_>,
    inertia: &Inertia,
) -> std::result::Result<Edit, String> {
    if let Some(old) = child(link, "inertial")? {
        let indent = indent_at(text, old.range().start);
        return Ok(Edit {
            range: old.range(),
            text: inertial_element(inertia, indent),
        });
    }
    let indent = indent_at(text, link.range().start);
    let inner = format!("{indent}  ");
    let (end, closed) = start_tag_end(text, link);
    let element = inertial_element(inertia, &inner);
    Ok(if closed {
        // <link name="x"/> becomes <link name="x">...</link>
        let name = link.tag_name().name();
        let prefix = &text[link.range().start + 1..];
        let qname = &prefix[..prefix
            .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
            .unwrap_or(name.len())];
        Edit {
            range: end - 1..end + 1,
            text: format!(">\n{inner}{element}\n{indent}</{qname}>"),
        }
    } else {
        Edit {
            range: end + 1..end + 1,
            text: format!("\n{inner}{element}"),
        }
    })
}

/// The edit that removes link element `link`'s `<inertial>` with its line, if it has one.
pub(super) fn remove_inertial(
    text: &str,
    link: roxmltree::Node<'_, '_>,
) -> std::result::Result<Option<Edit>, String> {
    let Some(old) = child(link, "inertial")? else {
        return Ok(None);
    };
    let mut range = old.range();
    let indent = indent_at(text, range.start);
    // the line too, where the element stands alone on it
    let line_end = ["\r\n", "\n"]
        .into_iter()
        .find(|e| text[range.end..].starts_with(e));
    let line_start = range.start - indent.len();
    if let Some(end) = line_end.filter(|_| line_start > 0 && text[..line_start].ends_with('\n')) {
        range = line_start..range.end + end.len();
    }
    Ok(Some(Edit {
        range,
        text: String::new(),
    }))
}

/// Escapes an attribute value written between double quotes.
pub(super) fn escape(value: &str) -> String {
    value
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// The edits that give joint element `joint` a `<dynamics>` with `values`: the values of those
/// attributes of its own replaced and the missing ones added to its start tag (every other
/// byte kept), or a new element before the joint's end tag.
pub(super) fn set_dynamics(
    text: &str,
    joint: roxmltree::Node<'_, '_>,
    dynamics: Option<roxmltree::Node<'_, '_>>,
    values: &[(&str, f64)],
) -> Vec<Edit> {
    if let Some(d) = dynamics {
        let (end, closed) = start_tag_end(text, d);
        // added before "/>" or ">"
        let at = if closed { end - 1 } else { end };
        return (values.iter())
            .map(|(k, v)| {
                let own = (d.attributes()).find(|a| a.namespace().is_none() && a.name() == *k);
                match own {
                    Some(a) => Edit {
                        range: a.range_value(),
                        text: number(*v),
                    },
                    None => Edit {
                        range: at..at,
                        text: format!(" {k}=\"{}\"", number(*v)),
                    },
                }
            })
            .collect();
    }
    let indent = indent_at(text, joint.range().start);
    let mut tag = String::from("<dynamics");
    for (k, v) in values {
        let _ = write!(tag, " {k}=\"{}\"", number(*v));
    }
    tag.push_str("/>");
    // before the end tag </joint>
    let close = text[..joint.range().end]
        .rfind("</")
        .unwrap_or(joint.range().end);
    let line_start = close - indent_at(text, close).len();
    vec![Edit {
        range: line_start..line_start,
        text: format!("{indent}  {tag}\n"),
    }]
}

/// The edit that attaches payload `p`: a link `name` and its fixed joint before `</robot>`.
pub(super) fn payload_edit(
    text: &str,
    model: &Model,
    elements: &Elements<'_, '_>,
    doc: &roxmltree::Document<'_>,
    p: &Payload,
    name: &str,
) -> std::result::Result<Edit, (String, String)> {
    let element = format!("payload link '{name}'");
    let joint = format!("{name}_joint");
    if name.is_empty() || name.chars().any(|c| c.is_control()) {
        return Err((
            element,
            "a link's name must be non-empty text without control characters".into(),
        ));
    }
    if elements.links.contains_key(name) || model.frame(name).is_some() {
        return Err((
            element,
            "a link of the robot has this name; choose another".into(),
        ));
    }
    if elements.joints.contains_key(joint.as_str()) {
        return Err((
            element,
            format!("its joint's name '{joint}' is a joint of the robot; choose another link name"),
        ));
    }
    if let Some(problem) = p.problem("payload") {
        return Err((element, problem));
    }
    if p.mass <= 0.0 {
        return Err((
            element,
            format!(
                "the payload's mass {} kg is not positive: nothing to attach",
                number(p.mass)
            ),
        ));
    }
    crate::model::payload::link_in_body(model, &p.link)
        .map_err(|e| (element.clone(), e.to_string()))?;
    let inertia = p.spatial_inertia();
    let root = doc.root_element();
    let close = text[..root.range().end]
        .rfind("</")
        .unwrap_or(root.range().end);
    let indent = "  ";
    let (name, joint, parent) = (escape(name), escape(&joint), escape(&p.link));
    Ok(Edit {
        range: close..close,
        text: format!(
            "{indent}<!-- a payload, attached by perturbid_rs: remove this link and its joint to take it off -->\n{indent}<link name=\"{name}\">\n{indent}  {}\n{indent}</link>\n{indent}<joint name=\"{joint}\" type=\"fixed\">\n{indent}  <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n{indent}  <parent link=\"{parent}\"/>\n{indent}  <child link=\"{name}\"/>\n{indent}</joint>\n",
            inertial_element(&inertia, &format!("{indent}  "))
        ),
    })
}

/// The comment that opens the robot: written by whom, from what.
pub(super) fn header(text: &str, doc: &roxmltree::Document<'_>, source: &str, note: &str) -> Edit {
    // "--" may not stand in a comment
    let clean = |s: &str| {
        let mut s: String = s
            .chars()
            .filter(|c| !c.is_control() || *c == '\n')
            .collect();
        while s.contains("--") {
            s = s.replace("--", "- -");
        }
        s
    };
    let mut comment = format!(
        "<!-- Written by perturbid_rs {} from '{}': the links' inertials and the joints' dynamics as the model has them, the rest as that file has it.",
        env!("CARGO_PKG_VERSION"),
        clean(source)
    );
    if !note.is_empty() {
        comment.push(' ');
        comment.push_str(&clean(note));
    }
    if comment.ends_with('-') {
        comment.push(' ');
    }
    comment.push_str(" -->\n");
    let start = doc.root_element().range().start;
    let start = start - indent_at(text, start).len();
    Edit {
        range: start..start,
        text: comment,
    }
}

/// The source text with the edits made (they do not overlap), their lines ended as the
/// source's are (`\r\n` where it has them).
pub(super) fn apply(text: &str, mut edits: Vec<Edit>) -> String {
    edits.sort_by_key(|e| (e.range.start, e.range.end));
    if text.contains("\r\n") {
        for e in &mut edits {
            e.text = e.text.replace('\n', "\r\n");
        }
    }
    let mut out =
        String::with_capacity(text.len() + edits.iter().map(|e| e.text.len()).sum::<usize>());
    let mut at = 0;
    for e in edits {
        out.push_str(&text[at..e.range.start]);
        out.push_str(&e.text);
        at = e.range.end;
    }
    out.push_str(&text[at..]);
    out
}
