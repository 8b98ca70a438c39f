//! Robots built into the library (embedded in the binary and the Python wheel).

pub mod a465;

use crate::error::{Error, Result};
use crate::model::Model;

/// Built-in robot names accepted by [`builtin`].
pub const BUILTIN: &[&str] = &[
    "a465",
    "a465:kinsheel2010",
    "a465:physical",
    "a465:kinsheel2010_lumped",
];

/// A built-in robot by name: `a465` (the `kinsheel2010` variant) or `a465:VARIANT`.
///
/// ```
/// let model = perturbid_rs::robots::builtin("a465:physical")?;
/// assert_eq!(model.nv, 6);
/// assert!(perturbid_rs::robots::builtin("puma").is_err());
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
pub fn builtin(name: &str) -> Result<Model> {
    builtin_with(name, &crate::urdf::LoadOptions::default())
}

/// [`builtin`] with load options (joints to lock; the triangle-inequality check is kept off
/// for the variants that need it).
pub fn builtin_with(name: &str, options: &crate::urdf::LoadOptions) -> Result<Model> {
    let (robot, variant) = name
        .split_once(':')
        .unwrap_or((name, a465::DEFAULT_VARIANT));
    match robot {
        "a465" => a465::model_with(variant, options),
        _ => Err(Error::UnknownRobot {
            name: name.to_string(),
            available: BUILTIN.iter().map(|s| s.to_string()).collect(),
        }),
    }
}
