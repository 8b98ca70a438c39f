//! What the sensors of the true robot do to the log: sample-time jitter, a torque delay,
//! encoder and torque quantisation, white or coloured torque noise (see
//! [`super::true_robot::Sensors`]).

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::true_robot::{per_joint, Sensors};
use crate::error::Result;

/// The true signals on the sampling grid (row-major, `n` per sample): what the encoders
/// would read without quantisation (`q`, rad, offsets included), the joint speeds (`qd`,
/// rad/s, for interpolation) and the torque the robot logs (`tau`, N m).
pub struct TrueSignals<'a> {
    pub n: usize,
    pub t: &'a [f64],
    pub q: &'a [f64],
    pub qd: &'a [f64],
    pub tau: &'a [f64],
}

impl TrueSignals<'_> {
    /// The interval `[t_i, t_i+1]` holding `time` (clamped to the grid) and the fraction in it.
    fn locate(&self, time: f64) -> (usize, f64) {
        let k = self.t.len();
        let time = time.clamp(self.t[0], self.t[k - 1]);
        let i = self.t.partition_point(|&x| x <= time).clamp(1, k - 1) - 1;
        let h = self.t[i + 1] - self.t[i];
        (i, if h > 0.0 { (time - self.t[i]) / h } else { 0.0 })
    }

    /// Position of joint `j` at `time`: cubic Hermite on positions and speeds (exact for
    /// polynomials up to degree 3).
    fn q_at(&self, j: usize, time: f64) -> f64 {
        let (i, s) = self.locate(time);
        let n = self.n;
        let h = self.t[i + 1] - self.t[i];
        let (p0, p1) = (self.q[i * n + j], self.q[(i + 1) * n + j]);
        let (m0, m1) = (self.qd[i * n + j] * h, self.qd[(i + 1) * n + j] * h);
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * p0
            + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * p1
            + (s3 - s2) * m1
    }

    /// Torque of joint `j` at `time`, linear between samples.
    fn tau_at(&self, j: usize, time: f64) -> f64 {
        let (i, s) = self.locate(time);
        let n = self.n;
        (1.0 - s) * self.tau[i * n + j] + s * self.tau[(i + 1) * n + j]
    }
}

/// The logged positions and torques (row-major) from the true signals: each sample taken at
/// its stamp plus a jitter (positions) and minus the delay (torques), then quantised, with
/// noise added to the torques. `rng` draws the jitter and the noise.
pub fn measure(
    sensors: &Sensors,
    signals: &TrueSignals<'_>,
    rng: &mut ChaCha8Rng,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let n = signals.n;
    let k = signals.t.len();
    let counts = per_joint("sensors.encoder_counts", &sensors.encoder_counts, n, 0.0)?;
    let sigma = per_joint("sensors.torque_noise", &sensors.torque_noise, n, 0.0)?;
    let rho = per_joint(
        "sensors.torque_noise_correlation",
        &sensors.torque_noise_correlation,
        n,
        0.0,
    )?;
    let resolution = per_joint(
        "sensors.torque_resolution",
        &sensors.torque_resolution,
        n,
        0.0,
    )?;
    let gauss = Normal::new(0.0, 1.0).expect("unit normal");
    let shifted = sensors.jitter > 0.0 || sensors.delay > 0.0;
    let mut noise = vec![0.0; n];
    let (mut q, mut tau) = (Vec::with_capacity(k * n), Vec::with_capacity(k * n));
    for i in 0..k {
        let when = if sensors.jitter > 0.0 {
            signals.t[i] + sensors.jitter * gauss.sample(rng)
        } else {
            signals.t[i]
        };
        for j in 0..n {
            let (mut p, mut f) = if shifted {
                (
                    signals.q_at(j, when),
                    signals.tau_at(j, when - sensors.delay),
                )
            } else {
                (signals.q[i * n + j], signals.tau[i * n + j])
            };
            if counts[j] > 0.0 {
                let step = std::f64::consts::TAU / counts[j];
                p = (p / step).round() * step;
            }
            if sigma[j] > 0.0 {
                let w = gauss.sample(rng);
                noise[j] = if i == 0 {
                    sigma[j] * w
                } else {
                    rho[j] * noise[j] + (1.0 - rho[j] * rho[j]).sqrt() * sigma[j] * w
                };
                f += noise[j];
            }
            if resolution[j] > 0.0 {
                f = (f / resolution[j]).round() * resolution[j];
            }
            q.push(p);
            tau.push(f);
        }
    }
    Ok((q, tau))
}
