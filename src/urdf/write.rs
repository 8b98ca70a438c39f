//! Writing a robot back as URDF: the file the model was read from, with every body whose
//! inertia changed (an identification, `ConsistentFit::robot`) given its new `<inertial>`,
//! every joint whose friction or armature changed its new `<dynamics>`, and a payload
//! attached as a link of its own. Everything else in the file (visuals, collisions, Gazebo and
//! transmission tags, comments, the order and spelling of elements) is kept byte for byte:
//! the edits replace only the elements they write.
//!
//! A moving body is the body's own link and every link behind fixed (or locked) joints that
//! moves with it; an identification determines the body's sum only. The other links keep the
//! URDF's inertials and the body's own link gets the rest, where that is a rigid body. Where
//! it is not, the links behind fixed joints give their inertials up to the body's own link
//! (removed, and said in the warnings); a locked joint's link keeps its own, as it moves once
//! the joint is unlocked. Where even that leaves no rigid body, every link of the body gives
//! its inertial up (the body's own link holds the identified body; a locked joint's link then
//! carries no mass, warned of). Where the body is no rigid body itself, nothing is written.
//!
//! The text written is read again with the same options, and every body's inertia, joint's
//! friction and armature must come back as the model has them (to 1e-9 of their size), or
//! nothing is returned.

use std::collections::HashMap;

use super::convert::link_inertia;
use super::edits::{
    apply, child, header, number, payload_edit, remove_inertial, set_dynamics, set_inertial, Edit,
    Elements,
};
use super::{lines, model_from_urdf_str};
use crate::error::{Error, Result};
use crate::model::payload::Payload;
use crate::model::Model;
use crate::parameters::{dynamic_parameters, inertia_from_parameters};
use crate::spatial::{rigid_body_problem, Inertia};

/// The longest note [`WriteOptions::note`] takes, in characters (a comment, not a log).
pub const MAX_NOTE: usize = 65_536;

/// The longest name of a payload's link [`WriteOptions::payload_link`] takes, in characters.
pub const MAX_LINK_NAME: usize = 4096;

/// What to write besides the model's own parameters.
#[derive(Clone, Debug)]
pub struct WriteOptions<'a> {
    /// A payload to attach: a link of its own (named `payload_link`, holding the payload's
    /// mass, centre of mass and inertia in its `<inertial>`) fixed to the payload's link by
    /// joint `<payload_link>_joint` at that link's origin, so that it can be taken off again.
    pub payload: Option<&'a Payload>,
    /// Name of the payload's link; it must be no link's or joint's name yet.
    pub payload_link: &'a str,
    /// Said in the comment the file opens with: where the parameters came from.
    pub note: &'a str,
}

impl Default for WriteOptions<'_> {
    fn default() -> Self {
        Self {
            payload: None,
            payload_link: "payload",
            note: "",
        }
    }
}

/// A URDF written by [`write_urdf`].
#[derive(Clone, Debug, PartialEq)]
pub struct WrittenUrdf {
    /// The URDF text (UTF-8).
    pub text: String,
    /// What was written, one sentence each: the links given new inertials, the joints new
    /// dynamics, the payload's link.
    pub notes: Vec<String>,
    /// What the file does not hold as the model does, one sentence each: a link's inertial
    /// moved onto its body's own link (the link then has none of its own), a gravity other
    /// than the standard 9.81 m/s^2 down the base's z axis (a URDF has no place for it).
    pub warnings: Vec<String>,
}

/// The URDF of `model`: the file it was built from with its changed inertias, friction
/// (`<dynamics damping friction>`: viscous N m s/rad or N s/m, Coulomb N m or N) and armature
/// (`<dynamics armature>`, kg m^2 or kg) written in, and `options.payload` attached as a link
/// of its own; every other byte of the file kept. Inertials are written in the link's frame
/// (`rpy="0 0 0"`, the centre of mass in m, the inertia about it in kg m^2, numbers that read
/// back exactly). A link moving with another's body (behind a fixed or locked joint) keeps
/// the file's inertial and the body's own link gets the rest, where that is a rigid body;
/// otherwise the links behind fixed joints, and then all of them, give theirs up to it (a
/// warning each). The text
/// is read back and compared with the model before it is returned (docs/urdf.md).
///
/// Refused (a `ModelError` naming the joint, link or field) where the model's kinematics or
/// limits differ from its file's (only inertias, friction and armature are written), where a
/// changed friction or armature is negative or an armature comes from a `<transmission>`,
/// where a body is no rigid body (nor is it less its other links' inertials), and where the
/// payload's link name is taken or the payload is no rigid body of positive mass.
pub fn write_urdf(model: &Model, options: &WriteOptions<'_>) -> Result<WrittenUrdf> {
    for (argument, value, most) in [
        ("note", options.note, MAX_NOTE),
        ("payload_link", options.payload_link, MAX_LINK_NAME),
    ] {
        let length = value.chars().count();
        if length > most {
            return Err(Error::invalid(
                argument,
                format!("{length} characters, expected at most {most}"),
            ));
        }
    }
    let source = &model.urdf;
    let text = source.text.as_str();
    let original = model_from_urdf_str(text, &model.source, &source.options)?;
    let refuse = |element: String, message: String| refusal(model, element, message);
    same_kinematics(model, &original).map_err(|(e, m)| refuse(e, m))?;
    let doc = lines::parse_xml(text, &model.source)?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| Error::UrdfSyntax {
        source_name: model.source.clone(),
        message: e.to_string(),
    })?;
    let file = File {
        model,
        original: &original,
        text,
        elements: Elements::of(&doc),
        // each link by name, and the joint each link hangs from
        links: robot.links.iter().map(|l| (l.name.as_str(), l)).collect(),
        parent_joint: (robot.joints.iter())
            .map(|j| (j.child.link.as_str(), j))
            .collect(),
    };
    let mut changes = Changes::default();
    for b in 0..model.bodies.len() {
        file.inertial_edits(b, &mut changes)?;
    }
    for j in 0..model.nv {
        file.dynamics_edits(j, &mut changes)?;
    }
    let Changes {
        mut edits,
        mut notes,
        mut warnings,
    } = changes;
    let elements = &file.elements;
    if let Some(p) = options.payload {
        edits.push(
            payload_edit(text, model, elements, &doc, p, options.payload_link)
                .map_err(|(e, m)| refuse(e, m))?,
        );
        notes.push(format!(
            "link '{}': the payload ({} kg), fixed to link '{}' by joint '{}_joint'",
            options.payload_link,
            number(p.mass),
            p.link,
            options.payload_link
        ));
    }
    // a URDF holds neither gravity's direction nor its size (readers take 9.81 m/s^2 down z)
    if model.gravity != nalgebra::Vector3::new(0.0, 0.0, -crate::model::STANDARD_GRAVITY) {
        warnings.push(format!(
            "gravity ({}, {}, {}) m/s^2 in the base frame: a URDF has no place for it",
            number(model.gravity.x),
            number(model.gravity.y),
            number(model.gravity.z)
        ));
    }
    edits.push(header(text, &doc, &model.source, options.note));
    let written = apply(text, edits);
    check_read_back(model, &written, options)?;
    Ok(WrittenUrdf {
        text: written,
        notes,
        warnings,
    })
}

/// A refusal to write `model`'s URDF, naming the element.
fn refusal(model: &Model, element: String, message: String) -> Error {
    Error::UrdfExport {
        robot: model.name.clone(),
        element,
        message,
    }
}

/// The edits of a URDF file, with what they did and what they could not keep.
#[derive(Default)]
struct Changes {
    edits: Vec<Edit>,
    notes: Vec<String>,
    warnings: Vec<String>,
}

/// The URDF a model came from, read for its edits.
struct File<'a, 'input> {
    model: &'a Model,
    /// The model the file itself builds.
    original: &'a Model,
    text: &'input str,
    elements: Elements<'a, 'input>,
    links: HashMap<&'a str, &'a urdf_rs::Link>,
    parent_joint: HashMap<&'a str, &'a urdf_rs::Joint>,
}

impl File<'_, '_> {
    /// Body `b`'s inertial rewritten where the model's differs from the file's: its own link
    /// holds what the links moving with it leave, or takes theirs over where the rest would be
    /// no rigid body.
    fn inertial_edits(&self, b: usize, changes: &mut Changes) -> Result<()> {
        let (model, original, text) = (self.model, self.original, self.text);
        let (links, parent_joint, elements) = (&self.links, &self.parent_joint, &self.elements);
        let refuse = |element: String, message: String| refusal(model, element, message);
        let triangle = (model.urdf.options.check_triangle_inequality).then_some("");
        let body = &model.bodies[b];
        let Changes {
            edits,
            notes,
            warnings,
        } = changes;
        if same_inertia(&body.inertia, &original.bodies[b].inertia) {
            return Ok(());
        }
        let others: Vec<Other> = (model.frames.iter())
            .filter(|f| f.body == Some(b) && f.link != body.link)
            .map(|f| Other {
                link: f.link.clone(),
                inertia: (links.get(f.link.as_str()))
                    .map_or(Inertia::zeros(), |l| f.pose.act_inertia(&link_inertia(l))),
                behind_locked: behind_locked(parent_joint, &body.link, &f.link),
            })
            .collect();
        // the allocations tried in turn: the other links keep theirs; those behind fixed
        // joints give theirs up; all of them do (a locked joint's link then carries no mass)
        let rigid = |r: &Inertia| rigid_body_problem(r.mass, &r.inertia_com, triangle).is_none();
        let allocations: [&dyn Fn(&Other) -> bool; 3] =
            [&|_| false, &|o| !o.behind_locked, &|_| true];
        let chosen = allocations.iter().find_map(|gives_up| {
            let kept = others.iter().filter(|o| !gives_up(o)).map(|o| &o.inertia);
            let moved: Vec<&Other> = (others.iter())
                .filter(|o| gives_up(o) && o.inertia.mass > 0.0)
                .collect();
            rest(&body.inertia, kept).filter(rigid).map(|r| (r, moved))
        });
        let Some((own, moved)) = chosen else {
            let problem = rest(&body.inertia, others.iter().map(|o| &o.inertia))
                .map_or("its mass is not above theirs".to_string(), |r| {
                    rigid_body_problem(r.mass, &r.inertia_com, triangle).unwrap_or_default()
                });
            return Err(refuse(
                format!("link '{}'", body.link),
                format!(
                    "body '{}' (joint '{}', mass {} kg) is no rigid body, nor is it less the URDF's inertials of the links that move with it ({}): {problem}",
                    body.link,
                    body.joint,
                    number(body.inertia.mass),
                    match others.is_empty() {
                        true => "none".to_string(),
                        false => (others.iter().map(|o| o.link.as_str())).collect::<Vec<_>>().join(", "),
                    },
                ),
            ));
        };
        let node = elements
            .link(&body.link)
            .map_err(|m| refuse(format!("link '{}'", body.link), m))?;
        edits.push(
            set_inertial(text, node, &own)
                .map_err(|m| refuse(format!("link '{}'", body.link), m))?,
        );
        notes.push(format!(
            "link '{}': a new <inertial> (mass {} kg)",
            body.link,
            number(own.mass)
        ));
        for o in moved {
            let node = elements
                .link(&o.link)
                .map_err(|m| refuse(format!("link '{}'", o.link), m))?;
            if let Some(edit) =
                remove_inertial(text, node).map_err(|m| refuse(format!("link '{}'", o.link), m))?
            {
                edits.push(edit);
            }
            warnings.push(format!(
                "link '{}': its <inertial> ({} kg) moved into link '{}' (the identified body less it is no rigid body){}",
                o.link,
                number(o.inertia.mass),
                body.link,
                match o.behind_locked {
                    true => "; the locked joint before it carries no mass in this file (unlocked, this library refuses it as massless)",
                    false => "",
                }
            ));
        }
        Ok(())
    }

    /// Joint `j`'s <dynamics> rewritten where the model's damping, friction or armature
    /// differ from the file's.
    fn dynamics_edits(&self, j: usize, changes: &mut Changes) -> Result<()> {
        let (model, original, text, elements) =
            (self.model, self.original, self.text, &self.elements);
        let refuse = |element: String, message: String| refusal(model, element, message);
        let Changes { edits, notes, .. } = changes;
        let (l, o) = (&model.limits[j], &original.limits[j]);
        let changed = l.damping != o.damping
            || l.friction != o.friction
            || model.armature[j] != original.armature[j];
        if !changed {
            return Ok(());
        }
        let name = &model.joint_names[j];
        let element = format!("joint '{name}'");
        for (field, v) in [
            ("damping", l.damping),
            ("friction", l.friction),
            ("armature", model.armature[j]),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(refuse(
                    element,
                    format!("{field} {} is not a finite number >= 0", number(v)),
                ));
            }
        }
        let node = elements
            .joint(name)
            .map_err(|m| refuse(element.clone(), m))?;
        let dynamics = child(node, "dynamics").map_err(|m| refuse(element.clone(), m))?;
        let armature_in_dynamics = dynamics.is_some_and(|d| d.attribute("armature").is_some());
        if model.armature[j] != original.armature[j]
            && original.armature[j] != 0.0
            && !armature_in_dynamics
        {
            return Err(refuse(
                element,
                format!(
                    "its armature ({} kg m^2) is given by a <transmission>, which is not rewritten; the new one is {}",
                    number(original.armature[j]),
                    number(model.armature[j])
                ),
            ));
        }
        let mut values = vec![("damping", l.damping), ("friction", l.friction)];
        if armature_in_dynamics || model.armature[j] != original.armature[j] {
            values.push(("armature", model.armature[j]));
        }
        edits.extend(set_dynamics(text, node, dynamics, &values));
        notes.push(format!(
            "joint '{name}': <dynamics> {}",
            values
                .iter()
                .map(|(k, v)| format!("{k}={}", number(*v)))
                .collect::<Vec<_>>()
                .join(" ")
        ));
        Ok(())
    }
}

/// A link moving with a body besides the body's own, with its URDF inertia in the body frame.
struct Other {
    link: String,
    inertia: Inertia,
    /// Whether a locked joint (one the URDF lets move) stands between the body's link and it.
    behind_locked: bool,
}

/// Whether a joint other than a fixed one lies on the path from link `from` down to `to`
/// (`parent_joint`: the joint each link hangs from).
fn behind_locked(parent_joint: &HashMap<&str, &urdf_rs::Joint>, from: &str, to: &str) -> bool {
    let mut link = to;
    let mut locked = false;
    while link != from {
        let Some(j) = parent_joint.get(link) else {
            return false;
        };
        locked |= j.joint_type != urdf_rs::JointType::Fixed;
        link = &j.parent.link;
    }
    locked
}

/// `whole` less `parts` (ten parameters each, in one frame), or None where no mass is left.
fn rest<'a>(whole: &Inertia, parts: impl Iterator<Item = &'a Inertia>) -> Option<Inertia> {
    let mut p = dynamic_parameters(whole);
    for part in parts {
        for (a, b) in p.iter_mut().zip(dynamic_parameters(part)) {
            *a -= b;
        }
    }
    inertia_from_parameters(&p)
}

/// Whether two inertias are one beyond rounding (1e-12 of their size).
fn same_inertia(a: &Inertia, b: &Inertia) -> bool {
    let (a, b) = (dynamic_parameters(a), dynamic_parameters(b));
    let scale = a.iter().chain(&b).fold(1e-300f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(&b)
        .all(|(x, y)| (x - y).abs() <= 1e-12 * scale)
}

/// The first field in which `model`'s kinematics or limits differ from `original`'s (the same
/// file read again), as (element, message).
fn same_kinematics(model: &Model, original: &Model) -> std::result::Result<(), (String, String)> {
    let not_written = "only inertias, friction and armature are written";
    if model.nbodies() != original.nbodies() || model.nv != original.nv {
        return Err((
            "robot".into(),
            format!(
                "it has {} bodies and {} joints, its URDF {} and {}",
                model.nbodies(),
                model.nv,
                original.nbodies(),
                original.nv
            ),
        ));
    }
    for (b, o) in model.bodies.iter().zip(&original.bodies) {
        let element = format!("joint '{}'", b.joint);
        if b.joint != o.joint || b.link != o.link || b.parent != o.parent {
            return Err((
                element,
                format!(
                    "the URDF's body here is joint '{}' moving link '{}'",
                    o.joint, o.link
                ),
            ));
        }
        let moved = (b.placement.translation - o.placement.translation).norm() > 1e-12
            || (b.placement.rotation - o.placement.rotation).norm() > 1e-12
            || (b.axis - o.axis).norm() > 1e-12
            || b.kind != o.kind
            || b.multiplier != o.multiplier
            || b.offset != o.offset;
        if moved {
            return Err((
                element,
                format!("its placement, axis or coupling differs from the URDF's; {not_written}"),
            ));
        }
    }
    for j in 0..model.nv {
        let (l, o) = (&model.limits[j], &original.limits[j]);
        for (field, a, b) in [
            ("lower", l.lower, o.lower),
            ("upper", l.upper, o.upper),
            ("velocity", l.velocity, o.velocity),
            ("effort", l.effort, o.effort),
            ("acceleration", l.acceleration, o.acceleration),
        ] {
            if a != b && !(a.is_nan() && b.is_nan()) {
                return Err((
                    format!("joint '{}'", model.joint_names[j]),
                    format!(
                        "its {field} limit {} differs from the URDF's {}; {not_written}",
                        number(a),
                        number(b)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Reads `written` back and compares it with what was meant: `model`, with the payload.
fn check_read_back(model: &Model, written: &str, options: &WriteOptions<'_>) -> Result<()> {
    let internal = |message: String| Error::Internal {
        context: "write_urdf".into(),
        message,
    };
    let back = model_from_urdf_str(written, &model.source, &model.urdf.options)
        .map_err(|e| internal(format!("the URDF written does not read back: {e}")))?;
    let mut meant: Vec<Inertia> = model.bodies.iter().map(|b| b.inertia).collect();
    if let Some(p) = options.payload {
        let (b, inertia) = p.in_body(model)?;
        meant[b] = meant[b].add(&inertia);
    }
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale.max(a.abs()).max(1e-300);
    for (b, body) in back.bodies.iter().enumerate() {
        let (x, y) = (
            dynamic_parameters(&body.inertia),
            dynamic_parameters(&meant[b]),
        );
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !x.iter().zip(&y).all(|(a, b)| close(*a, *b, scale)) {
            return Err(internal(format!(
                "body '{}' reads back as {x:?}, expected {y:?}",
                model.bodies[b].link
            )));
        }
    }
    for j in 0..model.nv {
        let pairs = [
            (back.limits[j].damping, model.limits[j].damping),
            (back.limits[j].friction, model.limits[j].friction),
            (back.armature[j], model.armature[j]),
        ];
        if !pairs.iter().all(|(a, b)| close(*a, *b, 0.0)) {
            return Err(internal(format!(
                "joint '{}' reads back with damping, friction, armature {:?}, expected {:?}",
                model.joint_names[j],
                pairs.map(|p| p.0),
                pairs.map(|p| p.1)
            )));
        }
    }
    Ok(())
}
