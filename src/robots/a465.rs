//! The CRS A465 arm of Kinsheel & Taha (ICARCV 2010), as documented in docs/a465.md:
//! six revolute joints, frames parallel to the base at q = 0 (arm pointing up).
//!
//! Variants:
//! - `kinsheel2010` (default): fitted to the paper's Tables 2 and 3, physically consistent,
//!   with the motors' reflected rotor inertia as each joint's armature (refitted from
//!   `kinsheel2010_lumped` by `examples/refit_a465.rs`, whose torques it reproduces).
//! - `kinsheel2010_lumped`: the first fit, the `physical` set plus a rotor inertia lumped into
//!   each link about its joint axis. Its link inertias break the triangle inequality, so it is
//!   loaded with that check off; kept to compare with.
//! - `physical`: inertial parameters estimated from a CAD export (16 kg moving mass).

use crate::error::{Error, Result};
use crate::model::Model;
use crate::urdf::{model_from_urdf_str, LoadOptions};

pub const DEFAULT_VARIANT: &str = "kinsheel2010";
pub const VARIANTS: &[&str] = &["kinsheel2010", "physical", "kinsheel2010_lumped"];

const KINSHEEL2010: &str = include_str!("a465_kinsheel2010.urdf");
const KINSHEEL2010_LUMPED: &str = include_str!("a465_kinsheel2010_lumped.urdf");
const PHYSICAL: &str = include_str!("a465_physical.urdf");

/// Gear ratios of joints 1-6 (motor turns per joint turn), from the A465 user guide.
pub const GEAR_RATIOS: [f64; 6] = [100.0, 100.0, 100.0, 101.0, 100.0, 101.0];

/// The paper's Table 2 operating point: joint positions q* (rad).
#[allow(clippy::approx_constant)] // the paper's printed values, not pi/4 etc.
pub const TABLE2_Q: [f64; 6] = [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0];
/// Table 2: joint velocities qd* (rad/s).
pub const TABLE2_QD: [f64; 6] = [0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140];
/// Table 2: joint accelerations qdd* (rad/s^2).
pub const TABLE2_QDD: [f64; 6] = [-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710];
/// Table 2: nominal torques Tn (N m), gravity and friction excluded.
pub const TABLE2_TORQUE: [f64; 6] = [-1.1883, -3.4797, -1.7304, -0.1377, -0.4466, 0.0539];
/// Table 3: first column of D at the operating point, "actual" row.
pub const TABLE3_D_COLUMN1: [f64; 6] = [9.956, 0.0, 0.0, -1.37, 0.0, -0.27];

/// The URDF text of a variant.
pub fn urdf(variant: &str) -> Result<&'static str> {
    match variant {
        "kinsheel2010" => Ok(KINSHEEL2010),
        "physical" => Ok(PHYSICAL),
        "kinsheel2010_lumped" => Ok(KINSHEEL2010_LUMPED),
        _ => Err(Error::UnknownRobot {
            name: format!("a465:{variant}"),
            available: VARIANTS.iter().map(|v| format!("a465:{v}")).collect(),
        }),
    }
}

/// The A465 model of a variant (`"kinsheel2010"` or `"physical"`).
pub fn model(variant: &str) -> Result<Model> {
    model_with(variant, &LoadOptions::default())
}

/// [`model`] with load options (joints to lock); the lumped variant is loaded with the
/// triangle-inequality check off whatever `options` say.
pub fn model_with(variant: &str, options: &LoadOptions) -> Result<Model> {
    let text = urdf(variant)?;
    let options = LoadOptions {
        check_triangle_inequality: options.check_triangle_inequality
            && variant != "kinsheel2010_lumped",
        ..options.clone()
    };
    model_from_urdf_str(text, &format!("a465:{variant}"), &options)
}
