//! What [`super::preprocess::preprocess`] is asked to do: the grid, the filter, trimming and
//! decimation, the screening, and averaging over periods.

/// Options of [`preprocess`](super::preprocess::preprocess). The defaults follow the common
/// protocol (and the reference result on the real Panda log, docs/data.md): 1 kHz, 4th-order
/// Butterworth at 10 Hz applied zero-phase to qd and tau, qdd from the filtered qd, 0.5 s
/// dropped at both ends, every 10th sample kept.
#[derive(Clone, Debug, PartialEq)]
pub struct PreprocessOptions {
    /// Uniform sampling rate after resampling (Hz).
    pub rate: f64,
    /// Low-pass cutoff (Hz); `None` switches filtering off.
    pub cutoff: Option<f64>,
    /// Butterworth order (each pass; zero-phase doubles it).
    pub order: usize,
    /// Also filter the positions (default false: encoders are precise and filtering lags
    /// nothing but can round corners).
    pub filter_position: bool,
    /// Seconds dropped at both ends (filter transients, ramps).
    pub trim: f64,
    /// Keep every `decimate`-th sample (1 keeps all).
    pub decimate: usize,
    /// At a gap longer than [`MAX_GAP_INTERVALS`] median sample intervals, split the log and
    /// preprocess each part on its own (filtered, differentiated and trimmed separately, then
    /// concatenated with the gap kept in `t`) instead of refusing it. Nothing is interpolated
    /// across a gap either way.
    ///
    /// [`MAX_GAP_INTERVALS`]: crate::limits::MAX_GAP_INTERVALS
    pub split_at_gaps: bool,
    /// Find the log's glitches (single samples far off the curve their neighbours follow)
    /// and replace them by the fit of their neighbours, and remove its dropouts (rows in which
    /// every joint of a signal reads exactly 0 while the robot moves), before anything else
    /// (default true; [`crate::logs::log_screening`]). They are listed in the result's
    /// [`Recording::glitches`](super::Recording::glitches) and [`Recording::dropouts`](super::Recording::dropouts).
    pub screen_glitches: bool,
    /// Average the log over the periods of its excitation in place of the low-pass filter
    /// and numerical derivatives (Swevers et al. 2007; [`crate::logs::period_average`]): after the
    /// screening, the result is one period, `q`, `qd`, `qdd` from the positions' first
    /// harmonics and `tau` from the torques' up to `cutoff`, sampled at `rate` and decimated;
    /// `trim`, `order` and `split_at_gaps` do not apply (a period holding a gap is left out),
    /// and `filter_position` is refused. None (the default): the filter.
    pub periods: Option<crate::logs::period_average::PeriodOptions>,
}

impl Default for PreprocessOptions {
    fn default() -> Self {
        Self {
            rate: 1000.0,
            cutoff: Some(10.0),
            order: 4,
            filter_position: false,
            trim: 0.5,
            decimate: 10,
            split_at_gaps: false,
            screen_glitches: true,
            periods: None,
        }
    }
}
