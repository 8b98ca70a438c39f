//! Joint trajectories: how a robot is moved through the operating point (the paper's eqs. 11-15)
//! or excited for the direct method, sampled into [`Samples`] and checked against the limits.

pub mod fourier;
pub mod limits;
pub mod piecewise;
pub mod samples;
pub mod transition;

pub use fourier::FourierTrajectory;
pub use limits::check_limits;
pub use piecewise::{quintic, Segment, SegmentKind, Trajectory};
pub use samples::Samples;
pub use transition::{transition, TransitionLimits};
