//! The logs wing: what a robot recorded, the checks that find what went wrong in it, and the
//! preprocessing that turns it into uniform samples for a fit.
//!
//! - [`recording`]: a run's logged time stamps, positions, torques (and velocities and
//!   accelerations when logged), with what the preprocessing found in it;
//! - the checks, one file each: glitches in a whole log ([`log_screening`]) or in a window
//!   ([`outliers`]), rows logged as zeros ([`log_dropouts`]) and frozen readings
//!   ([`frozen_readings`]), columns logged at a lower rate and held ([`held_columns`]), steps of
//!   whole turns ([`position_wraps`]), jittering stamps ([`stamp_jitter`]), clipped torques
//!   ([`torque_saturation`]), logged derivatives against the positions' ([`derivative_columns`]),
//!   positions in coarse counts ([`position_rounding`]), samples given twice
//!   ([`repeated_samples`]);
//! - the preprocessing: a filter and numerical derivatives ([`preprocess`]), or averaging over
//!   the periods of a periodic excitation ([`period_average`], whose start [`excitation_start`]
//!   finds);
//! - recordings and trajectories as CSV ([`recording_csv`]);
//! - what the preprocessing found in a log, named by it ([`log_findings`]);
//! - several runs stacked for one fit ([`stacked_states`]), and several logs split into the
//!   samples to fit to and those to validate on ([`log_set`]).

pub mod derivative_columns;
pub mod excitation_start;
pub mod findings;
pub mod frozen_readings;
pub mod gaps;
pub mod held_columns;
pub mod log_dropouts;
pub mod log_findings;
pub mod log_screening;
pub mod log_set;
pub mod outliers;
pub mod period_average;
pub mod position_rounding;
pub mod position_wraps;
pub mod preprocess;
pub mod preprocess_options;
pub mod recording;
pub mod recording_csv;
pub mod repeated_samples;
pub mod stacked_states;
pub mod stamp_jitter;
pub mod torque_saturation;

pub use recording::Recording;
pub use recording_csv::{
    load_recording, read_recording, read_states, recording_table, samples_table, save_recording,
};
