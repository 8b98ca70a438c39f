//! Where each joint and link stands in the URDF text (urdf-rs keeps no positions).

use std::collections::HashMap;

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
        if let Ok(doc) = roxmltree::Document::parse(text) {
            for node in doc.root_element().children().filter(|n| n.is_element()) {
                let Some(name) = node.attribute("name") else {
                    continue;
                };
                let line = doc.text_pos_at(node.range().start).row;
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
