//! The perturbations of an experiment (the paper's Sec. IV): K deltas of the perturbed variable
//! around the operating point, in symmetric `+delta, -delta` pairs.

use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::choice::choice;
use crate::error::{Error, Result};

choice! {
    /// How the K perturbations are chosen.
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum Design ("design") {
        /// The paper's draws near the nominal (its Fig. 1): every joint uniform in
        /// `[-size, size]`, seeded.
        Random = "random",
        /// A designed set with `cond(X) = 1` once each column is divided by its joint's size:
        /// Sylvester-Hadamard columns (every joint at full size in every crossing) when K/2 is a
        /// multiple of the power of two above N, otherwise seeded random orthonormal columns.
        Orthogonal = "orthogonal" | "designed",
    }
}

/// A perturbation size: per joint, in the variable's units, or as a fraction of the joint's
/// limit (position: of the range `upper - lower`; velocity and acceleration: of the limit).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Size {
    Absolute(Vec<f64>),
    Fraction(f64),
}

impl Size {
    /// The size of every joint. `limits` are the joint's limits of this variable (range for
    /// positions); where a limit is infinite, `fallback` (absolute, in the variable's units)
    /// is used.
    pub fn resolve(&self, argument: &str, limits: &[f64], fallback: f64) -> Result<Vec<f64>> {
        let sizes: Vec<f64> = match self {
            Size::Absolute(v) => {
                if v.len() != limits.len() {
                    return Err(Error::shape(
                        argument,
                        format!("{} sizes (one per joint)", limits.len()),
                        format!("{} sizes", v.len()),
                    ));
                }
                v.clone()
            }
            Size::Fraction(f) => limits
                .iter()
                .map(|&l| if l.is_finite() { f * l } else { fallback })
                .collect(),
        };
        if let Some((j, s)) = sizes
            .iter()
            .enumerate()
            .find(|(_, s)| !(s.is_finite() && **s > 0.0))
        {
            return Err(Error::invalid(
                format!("{argument}[{j}]"),
                format!("perturbation size {s}; expected a positive finite number"),
            ));
        }
        if let Some((j, s)) = sizes
            .iter()
            .enumerate()
            .find(|(_, s)| **s < crate::limits::MIN_PERTURBATION)
        {
            return Err(Error::invalid(
                format!("{argument}[{j}]"),
                format!(
                    "perturbation size {}; expected at least {:e}, a hundredth of the finest encoders' step: a smaller one moves no torque a sensor reads",
                    crate::error::shown(*s),
                    crate::limits::MIN_PERTURBATION
                ),
            ));
        }
        Ok(sizes)
    }
}

/// Default perturbation sizes: 1 % of the position range, 5 % of the speed limit, 5 % of the
/// acceleration limit; where a limit is infinite, 0.02 rad, 0.1 rad/s, 0.5 rad/s^2.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sizes {
    pub position: Size,
    pub velocity: Size,
    pub acceleration: Size,
}

impl Sizes {
    /// The sizes per joint for `model`, `[position, velocity, acceleration]` (rad, rad/s,
    /// rad/s^2; m for prismatic joints): fractions of the position range and of the speed and
    /// acceleration limits, [`FALLBACK_SIZES`] where a limit is infinite.
    pub fn resolve_for(&self, model: &crate::model::Model) -> Result<[Vec<f64>; 3]> {
        let range: Vec<f64> = model.limits.iter().map(|l| l.upper - l.lower).collect();
        Ok([
            self.position
                .resolve("position size", &range, FALLBACK_SIZES[0])?,
            self.velocity
                .resolve("velocity size", &model.velocity_limit(), FALLBACK_SIZES[1])?,
            self.acceleration.resolve(
                "acceleration size",
                &model.acceleration_limit(),
                FALLBACK_SIZES[2],
            )?,
        ])
    }
}

impl Default for Sizes {
    fn default() -> Self {
        Self {
            position: Size::Fraction(0.01),
            velocity: Size::Fraction(0.05),
            acceleration: Size::Fraction(0.05),
        }
    }
}

/// Fallback sizes where a limit is infinite (position, velocity, acceleration).
pub const FALLBACK_SIZES: [f64; 3] = [0.02, 0.1, 0.5];

/// `count x n` perturbations of `design`, joint `j` scaled by `size[j]`. With `symmetric`, rows
/// come in pairs `(+delta, -delta)` (rows `2i` and `2i + 1`), which needs an even `count >= 2n`;
/// otherwise `count >= n`. Seeded by `seed`.
pub fn perturbations(
    design: Design,
    count: usize,
    size: &[f64],
    symmetric: bool,
    seed: u64,
) -> Result<DMatrix<f64>> {
    perturbations_of(design, count, size, symmetric, seed, true)
}

/// [`perturbations`] whose magnitudes vary from crossing to crossing for every joint: the
/// orthogonal design without its Sylvester-Hadamard columns (seeded random orthonormal columns
/// instead, still `cond(X) = 1`). The friction-aware H regression needs it: its Coulomb-step
/// column `sign(qd* + d) - sign(qd* - d)` is `sign(d)`, which a column of `+-size` equals up
/// to scale wherever the perturbations reverse the joint, leaving the regression
/// rank-deficient.
pub fn varying_perturbations(
    design: Design,
    count: usize,
    size: &[f64],
    symmetric: bool,
    seed: u64,
) -> Result<DMatrix<f64>> {
    perturbations_of(design, count, size, symmetric, seed, false)
}

fn perturbations_of(
    design: Design,
    count: usize,
    size: &[f64],
    symmetric: bool,
    seed: u64,
    hadamard: bool,
) -> Result<DMatrix<f64>> {
    let n = size.len();
    let needed = if symmetric { 2 * n } else { n };
    if count < needed || (symmetric && count % 2 == 1) {
        return Err(Error::invalid(
            "n (perturbations per experiment)",
            if symmetric {
                format!("{count}; symmetric pairs need an even number >= 2N = {needed}")
            } else {
                format!("{count}; need at least N = {n}")
            },
        ));
    }
    let m = if symmetric { count / 2 } else { count };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let unit = match design {
        Design::Random => DMatrix::from_fn(m, n, |_, _| rng.random_range(-1.0..=1.0)),
        Design::Orthogonal => orthogonal_unit(m, n, &mut rng, hadamard),
    };
    let mut out = DMatrix::zeros(count, n);
    for i in 0..m {
        for j in 0..n {
            let v = unit[(i, j)] * size[j];
            if symmetric {
                out[(2 * i, j)] = v;
                out[(2 * i + 1, j)] = -v;
            } else {
                out[(i, j)] = v;
            }
        }
    }
    Ok(out)
}

/// An `m x n` matrix (m >= n) with orthogonal columns of equal norm and entries in [-1, 1].
///
/// When `m` is a multiple of `p`, the smallest power of two `>= n` (`> n` when possible, to skip
/// the all-ones column), the rows of the `p x p` Sylvester-Hadamard matrix repeated: entries
/// +-1, every joint at full size in every crossing. Otherwise, or without `hadamard`, seeded
/// random orthonormal columns scaled so the largest entry is 1.
fn orthogonal_unit(m: usize, n: usize, rng: &mut ChaCha8Rng, hadamard: bool) -> DMatrix<f64> {
    let p = (n + 1).next_power_of_two();
    let (p, skip) = if m.is_multiple_of(p) {
        (p, 1)
    } else {
        (
            n.next_power_of_two(),
            usize::from(n.next_power_of_two() > n),
        )
    };
    if hadamard && m.is_multiple_of(p) && p >= n + skip {
        // Sylvester: H[i][j] = (-1)^popcount(i & j)
        return DMatrix::from_fn(m, n, |i, j| {
            if ((i % p) & (j + skip)).count_ones() % 2 == 0 {
                1.0
            } else {
                -1.0
            }
        });
    }
    let g = DMatrix::from_fn(m, n, |_, _| rng.sample::<f64, _>(StandardNormal));
    let q = g.qr().q();
    let max = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    q / max
}
