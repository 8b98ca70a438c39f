//! Fourier excitation trajectories (Swevers et al. 2007; the paper's eq. 16):
//! `q_i(t) = q_i0 + sum_l [a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t)]`.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::samples::Samples;
use crate::error::{Error, Result};

/// A periodic excitation of `n` joints with `L` harmonics of the base pulsation `w_f` (rad/s;
/// period `2 pi / w_f`). `a` and `b` are `n x L` (rad/s: they are velocity amplitudes), `q0`
/// the offsets (rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FourierTrajectory {
    pub w_f: f64,
    pub q0: Vec<f64>,
    #[serde(with = "crate::json::rows")]
    pub a: DMatrix<f64>,
    #[serde(with = "crate::json::rows")]
    pub b: DMatrix<f64>,
}

impl FourierTrajectory {
    /// Checks the shapes (`a`, `b`: `len(q0) x L`, `1 <= L <= MAX_HARMONICS`), finiteness,
    /// `w_f / 2 pi` within [`crate::limits::BASE_FREQUENCY`], and that the positions, velocities and accelerations stay within f64's range.
    pub fn new(w_f: f64, q0: Vec<f64>, a: DMatrix<f64>, b: DMatrix<f64>) -> Result<Self> {
        let n = q0.len();
        let (low, high) = crate::limits::BASE_FREQUENCY;
        let hz = w_f / std::f64::consts::TAU;
        // (a designed frequency at a bound may come back a rounding below it)
        if !(w_f.is_finite() && (low * (1.0 - 1e-12)..=high * (1.0 + 1e-12)).contains(&hz)) {
            return Err(Error::invalid(
                "base pulsation",
                format!(
                    "{} rad/s (a base frequency of {} Hz); expected a base frequency in [{low}, {high}] Hz",
                    crate::error::shown(w_f),
                    crate::error::shown(hz)
                ),
            ));
        }
        for (name, m) in [("a", &a), ("b", &b)] {
            if m.nrows() != n || m.ncols() == 0 || m.ncols() != a.ncols() {
                return Err(Error::shape(
                    name,
                    format!("{n} x L (one row per joint, L >= 1 harmonics, a and b alike)"),
                    format!("{} x {}", m.nrows(), m.ncols()),
                ));
            }
        }
        for (name, v) in [
            ("q0", &DMatrix::from_row_slice(1, n, &q0)),
            ("a", &a),
            ("b", &b),
        ] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFiniteInput {
                    argument: name.into(),
                    index: i,
                    value: v[i],
                });
            }
        }
        crate::limits::check_count("harmonics", a.ncols(), 1, crate::limits::MAX_HARMONICS)?;
        // the bounds of |q|, |qd| and |qdd| over time: coefficients whose sum leaves f64's
        // range would sample to inf or NaN
        for i in 0..n {
            let (mut q, mut v, mut acc) = (q0[i].abs(), 0.0, 0.0);
            for l in 0..a.ncols() {
                let w = w_f * (l + 1) as f64;
                let c = a[(i, l)].abs() + b[(i, l)].abs();
                q += c / w;
                v += c;
                acc += c * w;
            }
            if let Some((what, _)) = [("positions", q), ("velocities", v), ("accelerations", acc)]
                .into_iter()
                .find(|(_, x)| !x.is_finite())
            {
                return Err(Error::invalid(
                    "a, b",
                    format!(
                        "joint {}: the coefficients (with w_f = {}) give {what} beyond f64's range; expected an excitation a robot can run",
                        i + 1,
                        crate::error::shown(w_f)
                    ),
                ));
            }
        }
        Ok(Self { w_f, q0, a, b })
    }

    /// Number of joints.
    pub fn n(&self) -> usize {
        self.q0.len()
    }

    /// Number of harmonics L.
    pub fn harmonics(&self) -> usize {
        self.a.ncols()
    }

    /// Period (s).
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.w_f
    }

    /// Position, velocity and acceleration of joint `i` at `t` (s), analytically.
    pub fn eval(&self, i: usize, t: f64) -> (f64, f64, f64) {
        let (mut q, mut v, mut acc) = (self.q0[i], 0.0, 0.0);
        for l in 0..self.harmonics() {
            let w = self.w_f * (l + 1) as f64;
            let (s, c) = (w * t).sin_cos();
            let (a, b) = (self.a[(i, l)], self.b[(i, l)]);
            q += (a * s - b * c) / w;
            v += a * c + b * s;
            acc += w * (-a * s + b * c);
        }
        (q, v, acc)
    }

    /// Samples at the times `t` (s).
    pub fn sample(&self, t: &[f64]) -> Samples {
        let n = self.n();
        let mut out = Samples::with_capacity(n, t.len());
        for &ti in t {
            out.t.push(ti);
            for i in 0..n {
                let (q, v, a) = self.eval(i, ti);
                out.q.push(q);
                out.qd.push(v);
                out.qdd.push(a);
            }
        }
        out
    }

    /// Samples over `periods` periods at `rate` Hz, from t = 0. Fails unless `periods` is
    /// positive and finite, `rate` positive and at most [`crate::limits::MAX_RATE`], and the
    /// samples within [`crate::limits::MAX_SAMPLES`] and, with the torques a simulation adds
    /// (`1 + 4 N` values a sample), [`crate::limits::MAX_VALUES`].
    pub fn sample_periods(&self, periods: f64, rate: f64) -> crate::error::Result<Samples> {
        use crate::error::shown;
        use crate::limits::{check_range, check_samples, MAX_RATE};
        check_range("periods", periods, f64::MIN_POSITIVE, f64::MAX)?;
        check_range("rate", rate, f64::MIN_POSITIVE, MAX_RATE)?;
        let count = (periods * self.period() * rate).round();
        check_samples("periods", count, 1 + 4 * self.n(), || {
            format!(
                "{} periods of {} s at {} Hz",
                shown(periods),
                shown(self.period()),
                shown(rate)
            )
        })?;
        let count = count as usize + 1;
        let t: Vec<f64> = (0..count).map(|i| i as f64 / rate).collect();
        Ok(self.sample(&t))
    }
}
