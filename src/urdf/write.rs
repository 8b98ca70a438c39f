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
//! (removed, and said in the notes); a locked joint's link keeps its own, as it moves once
//! the joint is unlocked. Where even that leaves no rigid body, nothing is written.
//!
//! The text written is read again with the same options, and every body's inertia, joint's
//! friction and armature must come back as the model has them (to 1e-9 of their size), or
//! nothing is returned.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::ops::Range;

use super::convert::link_inertia;
use super::{lines, model_from_urdf_str, LoadOptions};
use crate::algorithms::regressor::{dynamic_parameters, inertia_from_parameters};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::rehearsal::Payload;
use crate::spatial::{rigid_body_problem, Inertia};

/// The URDF text a model was built from and the options it was built with: what
/// [`write_urdf`] edits.
#[derive(Clone)]
pub struct UrdfSource {
    pub(crate) text: String,
    pub(crate) options: LoadOptions,
}

impl std::fmt::Debug for UrdfSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "UrdfSource({} bytes, lock {:?})",
            self.text.len(),
            self.options.lock
        )
    }
}

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
    /// than straight down the base's z axis (a URDF has no place for it).
    pub warnings: Vec<String>,
}

/// One replacement of the source text.
struct Edit {
    range: Range<usize>,
    text: String,
}

/// The URDF of `model`: the file it was built from with its changed inertias, friction
/// (`<dynamics damping friction>`: viscous N m s/rad or N s/m, Coulomb N m or N) and armature
/// (`<dynamics armature>`, kg m^2 or kg) written in, and `options.payload` attached (see [this
/// module](self)). Inertials are written in the link's frame (`rpy="0 0 0"`, the centre of
/// mass in m, the inertia about it in kg m^2, numbers that read back exactly).
///
/// Refused (a `ModelError` naming the joint, link or field) where the model's kinematics or
/// limits differ from its file's (only inertias, friction and armature are written), where a
/// changed friction or armature is negative or an armature comes from a `<transmission>`,
/// where a body's inertia leaves no rigid body for its own link, and where the payload's link
/// name is taken or the payload is no rigid body of positive mass.
pub fn write_urdf(model: &Model, options: &WriteOptions<'_>) -> Result<WrittenUrdf> {
    let source = &model.urdf;
    let text = source.text.as_str();
    let original = model_from_urdf_str(text, &model.source, &source.options)?;
    let refuse = |element: String, message: String| Error::UrdfExport {
        robot: model.name.clone(),
        element,
        message,
    };
    same_kinematics(model, &original).map_err(|(e, m)| refuse(e, m))?;
    let doc = lines::parse_xml(text, &model.source)?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| Error::UrdfSyntax {
        source_name: model.source.clone(),
        message: e.to_string(),
    })?;
    let elements = Elements::of(&doc);
    let mut edits = Vec::new();
    let mut notes = Vec::new();
    let mut warnings = Vec::new();
    let triangle = source.options.check_triangle_inequality.then_some("");
    for (b, body) in model.bodies.iter().enumerate() {
        if same_inertia(&body.inertia, &original.bodies[b].inertia) {
            continue;
        }
        let others: Vec<Other> = (model.frames.iter())
            .filter(|f| f.body == Some(b) && f.link != body.link)
            .map(|f| {
                let link = robot.links.iter().find(|l| l.name == f.link);
                Other {
                    link: f.link.clone(),
                    inertia: link
                        .map_or(Inertia::zeros(), |l| f.pose.act_inertia(&link_inertia(l))),
                    behind_locked: behind_locked(&robot, &body.link, &f.link),
                }
            })
            .collect();
        let all = rest(&body.inertia, others.iter().map(|o| &o.inertia));
        let (own, moved) = match all
            .filter(|r| rigid_body_problem(r.mass, &r.inertia_com, triangle).is_none())
        {
            Some(r) => (r, Vec::new()),
            None => {
                let locked = others
                    .iter()
                    .filter(|o| o.behind_locked)
                    .map(|o| &o.inertia);
                let fixed: Vec<&Other> = (others.iter())
                    .filter(|o| !o.behind_locked && o.inertia.mass > 0.0)
                    .collect();
                let r = rest(&body.inertia, locked).filter(|r| {
                    !fixed.is_empty()
                        && rigid_body_problem(r.mass, &r.inertia_com, triangle).is_none()
                });
                match r {
                    Some(r) => (r, fixed),
                    None => {
                        return Err(refuse(
                            format!("link '{}'", body.link),
                            format!(
                                "body '{}' (joint '{}', mass {} kg) leaves its own link no rigid body beside the URDF's inertials of the links that move with it ({}): {}",
                                body.link,
                                body.joint,
                                number(body.inertia.mass),
                                if others.is_empty() { "none".to_string() } else { others.iter().map(|o| o.link.as_str()).collect::<Vec<_>>().join(", ") },
                                match all {
                                    Some(r) => rigid_body_problem(r.mass, &r.inertia_com, triangle).unwrap_or_default(),
                                    None => "its mass is not above theirs".into(),
                                }
                            ),
                        ))
                    }
                }
            }
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
                "link '{}': its <inertial> ({} kg) moved into link '{}' (the identified body less it is no rigid body)",
                o.link,
                number(o.inertia.mass),
                body.link
            ));
        }
    }
    for j in 0..model.nv {
        let (l, o) = (&model.limits[j], &original.limits[j]);
        let changed = l.damping != o.damping
            || l.friction != o.friction
            || model.armature[j] != original.armature[j];
        if !changed {
            continue;
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
        if model.armature[j] != 0.0 || armature_in_dynamics {
            values.push(("armature", model.armature[j]));
        }
        edits.push(set_dynamics(text, node, dynamics, &values));
        notes.push(format!(
            "joint '{name}': <dynamics> {}",
            values
                .iter()
                .map(|(k, v)| format!("{k}={}", number(*v)))
                .collect::<Vec<_>>()
                .join(" ")
        ));
    }
    if let Some(p) = options.payload {
        edits.push(
            payload_edit(text, model, &elements, &doc, p, options.payload_link)
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
    let standard = nalgebra::Vector3::new(0.0, 0.0, -1.0);
    if (model.gravity.normalize() - standard).norm() > 1e-12 {
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

/// A link moving with a body besides the body's own, with its URDF inertia in the body frame.
struct Other {
    link: String,
    inertia: Inertia,
    /// Whether a locked joint (one the URDF lets move) stands between the body's link and it.
    behind_locked: bool,
}

/// Whether a joint other than a fixed one lies on the path from link `from` down to `to`.
fn behind_locked(robot: &urdf_rs::Robot, from: &str, to: &str) -> bool {
    let mut link = to;
    let mut locked = false;
    while link != from {
        let Some(j) = robot.joints.iter().find(|j| j.child.link == link) else {
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
struct Elements<'a, 'input> {
    links: HashMap<&'a str, roxmltree::Node<'a, 'input>>,
    joints: HashMap<&'a str, roxmltree::Node<'a, 'input>>,
}

impl<'a, 'input> Elements<'a, 'input> {
    fn of(doc: &'a roxmltree::Document<'input>) -> Self {
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

    fn link(&self, name: &str) -> std::result::Result<roxmltree::Node<'a, 'input>, String> {
        self.links
            .get(name)
            .copied()
            .ok_or_else(|| "no <link> of this name in the file".into())
    }

    fn joint(&self, name: &str) -> std::result::Result<roxmltree::Node<'a, 'input>, String> {
        self.joints
            .get(name)
            .copied()
            .ok_or_else(|| "no <joint> of this name in the file".into())
    }
}

/// The one child element `name` of `node`, if any; two are refused (readers differ on which
/// counts).
fn child<'a, 'input>(
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
fn indent_at(text: &str, offset: usize) -> &str {
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
fn start_tag_end(text: &str, node: roxmltree::Node<'_, '_>) -> (usize, bool) {
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
fn inertial_element(inertia: &Inertia, indent: &str) -> String {
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
fn set_inertial(
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
fn remove_inertial(
    text: &str,
    link: roxmltree::Node<'_, '_>,
) -> std::result::Result<Option<Edit>, String> {
    let Some(old) = child(link, "inertial")? else {
        return Ok(None);
    };
    let mut range = old.range();
    let indent = indent_at(text, range.start);
    if text[range.end..].starts_with('\n')
        && range.start - indent.len() > 0
        && text[..range.start - indent.len()].ends_with('\n')
    {
        range = range.start - indent.len()..range.end + 1;
    }
    Ok(Some(Edit {
        range,
        text: String::new(),
    }))
}

/// Escapes an attribute value written between double quotes.
fn escape(value: &str) -> String {
    value
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// The edit that gives joint element `joint` a `<dynamics>` with `values`: those attributes
/// of its own replaced (the others kept), or a new element before the joint's end tag.
fn set_dynamics(
    text: &str,
    joint: roxmltree::Node<'_, '_>,
    dynamics: Option<roxmltree::Node<'_, '_>>,
    values: &[(&str, f64)],
) -> Edit {
    let attributes = |kept: &mut String| {
        for (k, v) in values {
            let _ = write!(kept, " {k}=\"{}\"", number(*v));
        }
    };
    if let Some(d) = dynamics {
        let (end, closed) = start_tag_end(text, d);
        let mut tag = String::from("<dynamics");
        for a in d
            .attributes()
            .filter(|a| !values.iter().any(|(k, _)| *k == a.name()))
        {
            let _ = write!(tag, " {}=\"{}\"", &text[a.range_qname()], escape(a.value()));
        }
        attributes(&mut tag);
        tag.push_str(if closed { "/>" } else { ">" });
        let start = d.range().start;
        return Edit {
            range: start..end + 1,
            text: tag,
        };
    }
    let indent = indent_at(text, joint.range().start);
    let mut tag = String::from("<dynamics");
    attributes(&mut tag);
    tag.push_str("/>");
    // before the end tag </joint>
    let close = text[..joint.range().end]
        .rfind("</")
        .unwrap_or(joint.range().end);
    let line_start = close - indent_at(text, close).len();
    Edit {
        range: line_start..line_start,
        text: format!("{indent}  {tag}\n"),
    }
}

/// The edit that attaches payload `p`: a link `name` and its fixed joint before `</robot>`.
fn payload_edit(
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
    crate::rehearsal::link_in_body(model, &p.link).map_err(|e| (element.clone(), e.to_string()))?;
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
            "{indent}<!-- the payload identified by perturbid_rs; remove this link and its joint to take it off -->\n{indent}<link name=\"{name}\">\n{indent}  {}\n{indent}</link>\n{indent}<joint name=\"{joint}\" type=\"fixed\">\n{indent}  <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n{indent}  <parent link=\"{parent}\"/>\n{indent}  <child link=\"{name}\"/>\n{indent}</joint>\n",
            inertial_element(&inertia, &format!("{indent}  "))
        ),
    })
}

/// The comment that opens the robot: written by whom, from what.
fn header(text: &str, doc: &roxmltree::Document<'_>, source: &str, note: &str) -> Edit {
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

/// The source text with the edits made (they do not overlap).
fn apply(text: &str, mut edits: Vec<Edit>) -> String {
    edits.sort_by_key(|e| (e.range.start, e.range.end));
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
