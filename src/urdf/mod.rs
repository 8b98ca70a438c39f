//! Building a [`Model`](crate::model::Model) from a URDF (parsed by urdf-rs).
//!
//! What is read: the kinematic tree (any tree, not only chains) of revolute, continuous,
//! prismatic and fixed joints; joint origins (xyz, rpy); axes (normalised); link inertials with
//! their origin and rpy (the inertia is rotated into the link frame); `<limit>` (URDF 1.2
//! `acceleration` included) and `<dynamics damping friction>`; the armature (reflected rotor
//! inertia, see `armature`); `<mimic>` couplings. Links behind
//! fixed joints are merged into their parent body. Joints can be locked at a position when the
//! model is built, which turns them into fixed joints.
//!
//! What is checked, each failure naming the file, line and element: the URDF syntax; floating,
//! planar and spherical joints; the number of root links; cycles; links that are the child of
//! two joints; unknown links; invalid inertias (negative mass, not positive semi-definite,
//! principal moments breaking the triangle inequality); zero or non-finite axes; non-finite
//! numbers; revolute or prismatic joints without `<limit>`; moving joints that carry no mass.

//!
//! The reader (`reader`: the entry points and the `Builder` the steps share) is split by
//! step: `lines` finds where each element stands in the file,
//! `checks` refuses what no robot can have, `graph` links joints and links into a tree,
//! `roles` resolves mimic couplings and locks, `bodies` merges links into moving bodies and
//! `assemble` numbers the degrees of freedom into a [`Model`](crate::model::Model); `convert` turns urdf-rs values
//! into ours. `write` writes a model back as URDF, its changed parameters in the file it came
//! from, through the text edits of `edits`.

mod armature;
mod assemble;
mod bodies;
mod checks;
mod convert;
mod edits;
mod graph;
mod lines;
mod reader;
mod roles;
mod write;

pub use crate::model::source::{LoadOptions, UrdfSource};
pub use lines::{MAX_XML_DEPTH, MAX_XML_ELEMENTS};
pub use reader::{model_from_urdf_file, model_from_urdf_str};
pub use write::{write_urdf, WriteOptions, WrittenUrdf};
