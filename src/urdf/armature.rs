//! The armature of each joint: the motor's rotor inertia reflected through the gearbox to the
//! joint (kg m^2 for a revolute joint, kg for a prismatic one), as Pinocchio's `armature` and
//! MuJoCo's joint `armature`. URDF has no element for it; two spellings in use are read:
//!
//! - `<joint ...><dynamics damping="0" armature="0.5"/></joint>` (the reflected value itself;
//!   urdfdom, and so Pinocchio, wants `damping` or `friction` beside it), and
//! - Drake's `<transmission>` with `<joint name="J"/>` and an `<actuator>` holding
//!   `<drake:rotor_inertia value="Ir"/>` and optionally `<drake:gear_ratio value="n"/>`:
//!   reflected `Ir n^2` (any namespace prefix; elements matched by local name).
//!
//! Each value must be a finite number >= 0, given once per joint, on a joint that drives its
//! own degree of freedom (not fixed, not a mimic follower); a locked joint's rotor does not
//! turn, so its armature has no effect.

use std::collections::HashMap;

use super::lines::Lines;
use crate::error::{Error, Location, Result};

/// One joint's armature and where it was given.
#[derive(Clone, Debug)]
pub(super) struct ArmatureEntry {
    pub(super) value: f64,
    pub(super) line: u32,
}

/// The armature given for each joint (by URDF joint name).
pub(super) fn read(
    text: &str,
    doc: &roxmltree::Document<'_>,
    source: &str,
) -> Result<HashMap<String, ArmatureEntry>> {
    let lines = Lines::new(text);
    let mut out: HashMap<String, ArmatureEntry> = HashMap::new();
    let error = |joint: &str, line: u32, message: String| Error::InvalidArmature {
        location: Box::new(Location {
            source: source.to_string(),
            line: Some(line),
        }),
        joint: joint.to_string(),
        message,
    };
    let number = |joint: &str, node: roxmltree::Node<'_, '_>, attribute: &str| -> Result<f64> {
        let line = lines.of(node.range().start);
        let what = format!("<{} {attribute}>", node.tag_name().name());
        let text = node
            .attribute(attribute)
            .ok_or_else(|| error(joint, line, format!("{what} is missing")))?;
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v < 1e12 => Ok(v),
            _ => Err(error(
                joint,
                line,
                format!("{what} is '{text}', expected a finite number"),
            )),
        }
    };
    let mut add = |joint: &str, value: f64, line: u32| -> Result<()> {
        if value < 0.0 {
            return Err(error(
                joint,
                line,
                format!("{value} is negative; a rotor inertia is >= 0"),
            ));
        }
        if let Some(first) = out.get(joint) {
            return Err(error(
                joint,
                line,
                format!("given again (first on line {})", first.line),
            ));
        }
        out.insert(joint.to_string(), ArmatureEntry { value, line });
        Ok(())
    };
    for node in doc.root_element().children().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "joint" => {
                let Some(name) = node.attribute("name") else {
                    continue;
                };
                for d in node.children().filter(|c| c.has_tag_name("dynamics")) {
                    if d.attribute("armature").is_some() {
                        let value = number(name, d, "armature")?;
                        add(name, value, lines.of(d.range().start))?;
                    }
                }
            }
            "transmission" => {
                let joints: Vec<_> = node
                    .children()
                    .filter(|c| c.tag_name().name() == "joint")
                    .filter_map(|c| c.attribute("name"))
                    .collect();
                for actuator in node
                    .children()
                    .filter(|c| c.tag_name().name() == "actuator")
                {
                    let find = |local: &str| {
                        actuator
                            .children()
                            .find(|c| c.is_element() && c.tag_name().name() == local)
                    };
                    let Some(rotor) = find("rotor_inertia") else {
                        continue;
                    };
                    let line = lines.of(rotor.range().start);
                    let [joint] = joints[..] else {
                        return Err(error(
                            joints.first().copied().unwrap_or("?"),
                            line,
                            format!(
                                "a transmission with a rotor inertia must name exactly one joint, this one names {}",
                                joints.len()
                            ),
                        ));
                    };
                    let inertia = number(joint, rotor, "value")?;
                    let ratio = match find("gear_ratio") {
                        Some(g) => number(joint, g, "value")?,
                        None => 1.0,
                    };
                    add(joint, inertia * ratio * ratio, line)?;
                }
            }
            _ => {}
        }
    }
    Ok(out)
}
