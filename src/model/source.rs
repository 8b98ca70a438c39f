//! What a model was built from: the options of the URDF reader, and the URDF text itself with
//! them, which [`crate::urdf::write_urdf`] edits to write a model's parameters back.

use std::collections::BTreeMap;

/// Options for building a model from a URDF.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Joints held at a fixed position (rad or m), by URDF joint name. A locked joint becomes a
    /// fixed joint (like Pinocchio's reduced model); mimic joints that follow it are locked too.
    pub lock: BTreeMap<String, f64>,
    /// Reject link inertias whose principal moments break the triangle inequality
    /// (`I1 + I2 >= I3`). On by default; turn it off for models that lump rotor inertia into a
    /// link about one axis only (the `kinsheel2010` A465 does).
    pub check_triangle_inequality: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            lock: BTreeMap::new(),
            check_triangle_inequality: true,
        }
    }
}

/// The URDF text a model was built from and the options it was built with: what
/// [`crate::urdf::write_urdf`] edits.
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
