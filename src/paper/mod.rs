//! The paper's experiment reproduced end to end on the built-in A465 (`kinsheel2010`): Table 2,
//! Table 3 and Figs. 3-5 of Kinsheel & Taha (2010), with the direct method beside the
//! perturbation method ([`reproduce`]), and its report ([`write_report`]: Markdown tables, SVG
//! figures). Compiled with the `cli` feature.

pub mod markdown;
mod report;
mod reproduce;
pub mod study;

pub use report::write_report;
pub use reproduce::*;
