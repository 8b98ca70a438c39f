//! Where an excitation may take the robot besides its joint limits: points on named frames
//! kept above a plane (the floor, a table) or inside a box, with a margin, and the joint
//! torques kept within the URDF's effort limits.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::Model;

/// The region a point must stay in (base frame, m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Region {
    /// The side of a plane the normal points to: `normal . p >= offset` (`normal` need not be
    /// unit length; it is normalised). The floor a robot stands on: normal (0, 0, 1), offset 0.
    Above { normal: [f64; 3], offset: f64 },
    /// An axis-aligned box: `min <= p <= max` component by component.
    Inside { min: [f64; 3], max: [f64; 3] },
}

/// A point fixed to a link that must stay in a region, by at least `margin` (m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CartesianConstraint {
    /// The link (URDF name; links merged into a body by fixed joints are found too).
    pub frame: String,
    /// The point in the link's frame (m; default its origin).
    #[serde(default)]
    pub point: [f64; 3],
    pub region: Region,
    /// Distance kept from the region's boundary (m, default 0.05).
    #[serde(default = "default_margin")]
    pub margin: f64,
}

fn default_margin() -> f64 {
    0.05
}

/// The largest coordinate (m) of a constraint's point, plane or box (and of a plane normal's
/// components): no robot reaches a thousand kilometres.
pub const MAX_COORDINATE: f64 = 1e6;

/// The margin (m) of a constraint is below this.
pub const MAX_MARGIN: f64 = 1e3;

impl CartesianConstraint {
    /// Checks the numbers and that `model` has the frame; returns the body the frame moves
    /// with (`None` for the base) and the point in that body's frame.
    pub(crate) fn resolve(&self, model: &Model) -> Result<(Option<usize>, Vector3<f64>)> {
        let bad = |message: String| Error::InvalidArgument {
            argument: format!("workspace constraint on '{}'", self.frame),
            message,
        };
        // lengths within any robot's reach (beyond, a slip of the exponent or units)
        let within = |v: &[f64]| v.iter().all(|x| x.abs() < MAX_COORDINATE);
        let shown = |v: &[f64]| {
            let each: Vec<String> = v.iter().map(|&x| crate::error::shown(x)).collect();
            format!("[{}]", each.join(", "))
        };
        if !within(&self.point) {
            return Err(bad(format!(
                "point {} (m) must lie within {MAX_COORDINATE:e} m of the frame's origin in every coordinate",
                shown(&self.point)
            )));
        }
        if !(0.0..MAX_MARGIN).contains(&self.margin) {
            return Err(bad(format!(
                "margin {} (m) must be from 0 to below {MAX_MARGIN} m",
                crate::error::shown(self.margin)
            )));
        }
        match &self.region {
            Region::Above { normal, offset } => {
                let n = Vector3::from(*normal);
                if !within(normal) || n.norm() < 1e-9 || !within(&[*offset]) {
                    return Err(bad(format!(
                        "the plane's normal {} must be a non-zero vector and it and its offset {} (m) within {MAX_COORDINATE:e} in size",
                        shown(normal),
                        crate::error::shown(*offset)
                    )));
                }
            }
            Region::Inside { min, max } => {
                if !within(min) || !within(max) || (0..3).any(|k| min[k] >= max[k]) {
                    return Err(bad(format!(
                        "the box needs min {} < max {} (m) in every coordinate, each within {MAX_COORDINATE:e} m",
                        shown(min),
                        shown(max)
                    )));
                }
            }
        }
        let frame = model.frame(&self.frame).ok_or_else(|| {
            bad(format!(
                "the robot '{}' has no link of this name (links: {})",
                model.name,
                model
                    .frames
                    .iter()
                    .map(|f| f.link.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        let p = frame.pose.rotation * Vector3::from(self.point) + frame.pose.translation;
        Ok((frame.body, p))
    }

    /// The signed distance (m) of `p` (base frame) inside the region, less the margin: >= 0
    /// where the point is allowed.
    pub fn slack(&self, p: &Vector3<f64>) -> f64 {
        let inside = match &self.region {
            Region::Above { normal, offset } => {
                let n = Vector3::from(*normal);
                (n.dot(p) - offset) / n.norm()
            }
            Region::Inside { min, max } => (0..3)
                .map(|k| (p[k] - min[k]).min(max[k] - p[k]))
                .fold(f64::INFINITY, f64::min),
        };
        inside - self.margin
    }
}

/// Workspace constraints from JSON: an array of `{"frame": LINK, "point": [x, y, z],
/// "region": {"above": {"normal": [..], "offset": ..}} or {"inside": {"min": [..], "max":
/// [..]}}, "margin": m}`. `context` names the source in errors, which give the line, column
/// and JSON path of the culprit. At most 1000 constraints.
pub fn workspace_from_json(text: &str, context: &str) -> Result<Vec<CartesianConstraint>> {
    crate::json::check_containers(text, context)?;
    let mut reader = serde_json::Deserializer::from_str(text);
    let out: Vec<CartesianConstraint> =
        serde_path_to_error::deserialize(&mut reader).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            Error::Json {
                context: context.to_string(),
                message: format!(
                    "{} (expected an array of {{\"frame\", \"point\", \"region\": {{\"above\": {{\"normal\", \"offset\"}}}} or {{\"inside\": {{\"min\", \"max\"}}}}, \"margin\"}})",
                    crate::json::describe_error_at(&inner, text, &path)
                ),
            }
        })?;
    reader.end().map_err(|e| Error::Json {
        context: context.to_string(),
        message: crate::json::describe_error(&e, text),
    })?;
    crate::limits::check_count("workspace constraints", out.len(), 0, 1000)?;
    Ok(out)
}
