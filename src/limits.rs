//! The sizes this library accepts from its input, checked before anything is allocated from
//! them, so that a typing slip (`rate=1e12`) or a hostile file gets an error naming the
//! parameter, its value and the limit instead of an abort on allocation or a run of hours.
//! docs/limits.md lists them with their reasons.

use crate::error::{Error, Result};

/// Samples in one trajectory, recording or resampled log: 10^8 (a day at 1 kHz).
pub const MAX_SAMPLES: f64 = 1e8;
/// Values (samples x columns, f64) of one sampled trajectory, recording or resampled log that
/// the library allocates from its input: 2^28, 2 GiB (a 7-joint arm's t, q, qd, qdd and tau for
/// two and a half hours at 1 kHz; about what [`MAX_TEXT_BYTES`] of CSV holds). A larger one is
/// refused before it is allocated instead of aborting the process on a smaller machine.
pub const MAX_VALUES: f64 = 268_435_456.0;
/// Moving bodies (joints with a degree of freedom, mimic joints included) of one model: 1,000.
/// A model's buffers grow as the square of it (the regressor of one sample is `n x 10 n`,
/// eight times over for the SIMD lanes): 1,000 bodies take about 1 GB.
pub const MAX_BODIES: usize = 1000;
/// Sampling rate (Hz): 10 MHz, far above any robot controller.
pub const MAX_RATE: f64 = 1e7;
/// Perturbations (crossings) per experiment.
pub const MAX_PERTURBATIONS: usize = 100_000;
/// The base frequencies (Hz) of a Fourier excitation, designed or read: a period from 1,000 s
/// down to a millisecond.
pub const BASE_FREQUENCY: (f64, f64) = (1e-3, 1e3);
/// The highest Butterworth order a preprocessing filter takes (each pass; zero-phase doubles
/// it): far above the 2 to 8 of practice, and each order costs one more first- or second-order
/// section per sample (an order of 1e9 allocated 5 GB and aborted).
pub const MAX_FILTER_ORDER: usize = 32;
/// The smallest perturbation a plan takes (rad or m, per second, per second squared): a
/// hundredth of the finest encoders' step (about 1e-7 rad at 2^26 counts a revolution). A
/// smaller one moves no torque a sensor reads, and underflows to 0 in a design's entries near
/// 1e-308.
pub const MIN_PERTURBATION: f64 = 1e-9;
/// Harmonics per joint of a Fourier excitation.
pub const MAX_HARMONICS: usize = 1_000;
/// Logs (or runs) fitted together in one identification.
pub const MAX_LOGS: usize = 1000;
/// Samples per period at which an excitation's criterion is evaluated.
pub const MAX_FIT_SAMPLES: usize = 1_000_000;
/// Criterion evaluations of one excitation design.
pub const MAX_EVALUATIONS: usize = 10_000_000;
/// Bytes read from one table or log (CSV): 2 GiB (about eight hours of a 7-joint arm at
/// 1 kHz with every column).
pub const MAX_TEXT_BYTES: u64 = 2 << 30;
/// Bytes read from one document (JSON, TOML, URDF): 256 MiB, far past any plan, model or robot.
pub const MAX_DOCUMENT_BYTES: u64 = 256 << 20;
/// Arrays and objects in one JSON document (a plan, a model, a true robot, an excitation, a
/// workspace): 1,000,000. A model of the largest robot (1,000 bodies) has some tens of
/// thousands (its matrices' rows); a parser holds about 80 bytes for each, so 256 MiB of empty
/// rows (`[0],`) would take 5 GB.
pub const MAX_JSON_CONTAINERS: usize = 1_000_000;
/// Bytes of one TOML configuration (a pipeline or a study): 1 MiB, hundreds of steps. The
/// TOML parser holds about 250 bytes for each byte of small inline tables, so a document of
/// [`MAX_DOCUMENT_BYTES`] would take tens of gigabytes; a pipeline is a few kilobytes.
pub const MAX_CONFIG_BYTES: usize = 1 << 20;
/// A number of a saved local model (a torque, an entry of D*, H*, G*, Gs or their standard
/// errors, a state of its operating point): at most 10^9 in size, beyond any robot's. Larger
/// ones are hand edits or corruption, and would overflow the fits that read them (their squares
/// summed over rows).
pub const MAX_MODEL_VALUE: f64 = 1e9;

/// The largest mass (kg) or inertia (kg m^2) accepted in a link or a payload.
pub const MAX_INERTIAL: f64 = 1e9;
/// A simulated sensor's noise: torque noise up to 10^6 N m (a slip of the exponent is an error,
/// not a recording of noise).
pub const MAX_TORQUE_NOISE: f64 = 1e6;
/// A simulated joint's friction: levels up to 10^6 (N m, or N m s/rad for viscous friction),
/// Stribeck speeds up to 10^6 rad/s, and the amplitudes of a true robot's position-dependent
/// friction, cogging and ripple up to 10^6 (a slip of the exponent is an error, not a robot
/// whose torques drown everything in friction).
pub const MAX_FRICTION: f64 = 1e6;
/// A simulated encoder's resolution, when it has one: 10^-12 to 1 (rad or m) a count (positions
/// divided by a finer one leave f64's range; every position of a coarser one reads 0).
pub const POSITION_RESOLUTION: (f64, f64) = (1e-12, 1.0);
/// A simulated torque sensor's resolution, when it has one: 10^-12 to 10^6 N m.
pub const TORQUE_RESOLUTION: (f64, f64) = (1e-12, 1e6);

/// The first of a sensor's `values` outside its `range` (`(low, high)`: 0 for none or within
/// `[low, high]` when `low > 0`, else within `[0, high]`), with what was expected, for the
/// error message.
pub fn outside_sensor_range(values: &[f64], (low, high): (f64, f64)) -> Option<(usize, String)> {
    use crate::error::shown;
    let fits = |x: f64| x == 0.0 || (low..=high).contains(&x);
    let i = values.iter().position(|&x| !fits(x))?;
    let expected = if low > 0.0 {
        format!("0 (none) or a value in [{}, {}]", shown(low), shown(high))
    } else {
        format!("a value in [0, {}]", shown(high))
    };
    Some((i, expected))
}

/// A recording's longest gap between time stamps, in multiples of its median interval, before
/// resampling refuses to fill it with interpolated values.
pub const MAX_GAP_INTERVALS: f64 = 20.0;

/// Fails unless `value` (the parameter `name`) is finite and in `[low, high]`.
pub fn check_range(name: &str, value: f64, low: f64, high: f64) -> Result<()> {
    if value.is_finite() && value >= low && value <= high {
        return Ok(());
    }
    let expected = if low == f64::MIN_POSITIVE {
        format!("a positive finite number up to {}", bound(high))
    } else {
        format!("a finite number in [{}, {}]", bound(low), bound(high))
    };
    Err(Error::invalid(
        name,
        format!("{}; expected {expected}", crate::error::shown(value)),
    ))
}

/// A range bound as a person reads it: `1e-9`, `0.5`, `1e7`.
fn bound(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e7) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Fails unless the count `value` (the parameter `name`) is in `[low, high]`.
pub fn check_count(name: &str, value: usize, low: usize, high: usize) -> Result<()> {
    if (low..=high).contains(&value) {
        return Ok(());
    }
    Err(Error::invalid(
        name,
        format!("{value}; expected {low} to {high}"),
    ))
}

/// The number of samples of `duration` seconds at `rate` Hz (both checked: finite, positive,
/// the rate at most [`MAX_RATE`]), at most [`MAX_SAMPLES`] and, with `columns` values each, at
/// most [`MAX_VALUES`] values; `what` names the result in errors.
pub fn sample_count(what: &str, duration: f64, rate: f64, columns: usize) -> Result<usize> {
    check_range("rate", rate, f64::MIN_POSITIVE, MAX_RATE)?;
    let count = duration * rate;
    let given = || {
        format!(
            "{} s at {} Hz",
            crate::error::shown(duration),
            crate::error::shown(rate)
        )
    };
    check_samples(what, count, columns, given)?;
    Ok(count as usize + 1)
}

/// Fails unless `values` (of one array the library would allocate) are at most
/// [`MAX_VALUES`]. `given` says what the array is (`"the regressor of 300 states"`) and `what`
/// names the argument that decides it, both for the error.
pub fn check_values(what: &str, values: f64, given: impl FnOnce() -> String) -> Result<()> {
    if values <= MAX_VALUES {
        return Ok(());
    }
    Err(Error::invalid(
        what,
        format!(
            "{} is {values:.3e} values; at most 2^28 (2 GiB) are made (docs/limits.md)",
            given()
        ),
    ))
}

/// Fails unless `intervals + 1` samples (`intervals` finite, not negative) of `columns` values
/// each are within [`MAX_SAMPLES`] and [`MAX_VALUES`]. `given` says where the count comes from
/// (`"4 s at 1000 Hz"`) and `what` names the result, both for the error.
pub fn check_samples(
    what: &str,
    intervals: f64,
    columns: usize,
    given: impl FnOnce() -> String,
) -> Result<()> {
    let samples = intervals + 1.0;
    let values = samples * columns.max(1) as f64;
    if intervals.is_finite() && intervals >= 0.0 && samples <= MAX_SAMPLES && values <= MAX_VALUES {
        return Ok(());
    }
    Err(Error::invalid(
        what,
        format!(
            "{} give {samples:.3e} samples of {columns} values ({values:.3e} values); at most {MAX_SAMPLES:e} samples and 2^28 values (2 GiB) are made (docs/limits.md)",
            given()
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_errors_print_their_bounds_readably() {
        let e = check_range("rate", -1.0, f64::MIN_POSITIVE, MAX_RATE).unwrap_err();
        assert_eq!(
            e.to_string(),
            "rate: -1; expected a positive finite number up to 1e7"
        );
        let e = check_range("--periods", f64::NAN, 1e-9, 1e6).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--periods: NaN; expected a finite number in [1e-9, 1000000]"
        );
    }
}
