//! What averaging over periods is asked for ([`PeriodOptions`]), and the bounds on it.

/// What [`average_periods`](super::average_periods) averages: the excitation's period and
/// harmonics, and where in the log its periods lie.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodOptions {
    /// The excitation's period (s): `1 / base frequency`, within 0.001 to 1,000 s.
    pub period: f64,
    /// The harmonics of the base frequency the positions hold (the excitation's `L`, 1 to
    /// [`crate::limits::MAX_HARMONICS`]): the positions are projected onto harmonics 0 to `L`.
    pub harmonics: usize,
    /// The log's time (s) at which a period starts (the excitation's `t = 0`, modulo the
    /// period); None: the log's first sample. [`crate::logs::excitation_start`] finds it from the
    /// excitation.
    pub start: Option<f64>,
    /// Whole periods left out after `start` (a lead-in, the first period's transient).
    pub skip: usize,
    /// At most this many periods averaged (None: every whole period in the log).
    pub count: Option<usize>,
}

impl PeriodOptions {
    /// Periods of `period` s with `harmonics` harmonics, from the log's first sample, every
    /// whole period averaged.
    pub fn new(period: f64, harmonics: usize) -> Self {
        Self {
            period,
            harmonics,
            start: None,
            skip: 0,
            count: None,
        }
    }
}

/// The periods averaged may last 0.001 to 1,000 s (base frequencies of 1 kHz to 1 mHz, as
/// [`crate::limits::BASE_FREQUENCY`]).
pub const PERIOD_RANGE: (f64, f64) = (
    1.0 / crate::limits::BASE_FREQUENCY.1,
    1.0 / crate::limits::BASE_FREQUENCY.0,
);

/// The most multiply-adds the projections may take (samples of the log's periods times
/// harmonics): about ten seconds' work. A 10 s period at 1 kHz with 10 Hz of torque band
/// takes 10^6 for each period and joint.
pub const MAX_PROJECTION_WORK: f64 = 2e10;

/// The most periods averaged (a 10 s period: 11 days of a log).
pub const MAX_PERIODS: usize = 100_000;
