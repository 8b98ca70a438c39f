//! Whether an experiment's perturbations moved the torques beyond their noise (our
//! extension; docs/method.md, section 4).
//!
//! Perturbations too small for the torque sensor, or a torque channel that does not follow the
//! robot, leave a regression of noise: its estimate has numbers, and standard errors as large,
//! but nothing in it is measured. Each joint's torque changes are tested against their
//! residuals (the regression's F statistic: the mean square the perturbations explain over the
//! residuals' mean square, about 1 for noise alone), Bonferroni over the joints; the experiment
//! is warned of when no joint's torque responds.
//!
//! With `+-` pairs the test reads the pairs' half-differences `(tau(+d) - tau(-d)) / 2` against
//! `(x(+d) - x(-d)) / 2`: they hold the same linear response (the estimate of the pairs is the
//! estimate of their half-differences) but not the even-order terms, which the pairs cancel from
//! the estimate and leave in the full regression's residuals (the velocity-squared terms of H,
//! gravity's curvature in G). Against those residuals a small but exact H* looks like noise.

use nalgebra::DMatrix;

use super::plan::{Experiment, ExperimentKind};

/// The chance that an experiment of noise alone passes for a response (over all its joints).
pub const FALSE_ALARM: f64 = 0.01;

/// One joint's response: its F statistic with its degrees of freedom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// The mean square the perturbations explain over the residuals' mean square.
    pub f: f64,
    /// `P(F > f)` for noise alone.
    pub p: f64,
}

/// The noise of one torque reading from pass to pass through one state, from a set of such
/// passes (the nominal experiment's crossings): each joint's variance of a reading about their
/// mean (N^2 m^2, or N^2) with its degrees of freedom. It holds what the samples' scatter about
/// a window's fit does not: noise slower than a window (a drifting or coloured sensor) and the
/// robot's repeatability.
#[derive(Clone, Debug, PartialEq)]
pub struct PassNoise {
    pub variance: Vec<f64>,
    pub dof: usize,
}

impl PassNoise {
    /// The scatter of `readings` (K readings of N torques, N m or N, all through one state)
    /// about their mean; None with fewer than 2, or readings of different lengths.
    pub fn of<'a>(readings: impl IntoIterator<Item = &'a [f64]>) -> Option<Self> {
        let readings: Vec<&[f64]> = readings.into_iter().collect();
        let k = readings.len();
        let n = readings.first()?.len();
        if k < 2 || readings.iter().any(|r| r.len() != n) {
            return None;
        }
        let variance = (0..n)
            .map(|j| {
                let mean = readings.iter().map(|r| r[j]).sum::<f64>() / k as f64;
                let ss: f64 = readings.iter().map(|r| (r[j] - mean).powi(2)).sum();
                ss / (k - 1) as f64
            })
            .collect();
        Some(Self {
            variance,
            dof: k - 1,
        })
    }
}

/// The degrees of freedom given to the noise where it is read from the samples' scatter about
/// their windows' fits (`u`: known rather than estimated), because the regression leaves no
/// residual degrees of freedom of its own: the F test is then taken with this many, close to
/// its chi-square limit. (Not a threshold: with any residual degrees of freedom, even 2, the
/// regression's own residuals are the noise.)
const KNOWN_NOISE_DOF: f64 = 1000.0;

/// Each joint's response in the regression `y = x B` (`x`: k x N perturbations measured, `y`:
/// k x N torque changes, N m; `u`: k x N the variance of each torque reading from its samples'
/// scatter, N^2 m^2), or None for a joint left out by `measured` (a flat channel). With
/// `in_pairs`, rows `2i` and `2i + 1` are a `+-` pair, read by their half-differences. The
/// noise is the residuals' mean square where the regression has residual degrees of freedom,
/// otherwise (a plan of `N` pairs) the mean of `u` or, where `passes` scatter beyond it (their
/// variance over `u`'s F test at [`FALSE_ALARM`]), the variance of a row from `passes` (a
/// half-difference of two readings: half a reading's), with its degrees of freedom: `u` alone
/// misses noise from pass to pass and would take a drifting sensor's noise for a response.
pub fn responses(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    u: &DMatrix<f64>,
    in_pairs: bool,
    measured: &[bool],
    passes: Option<&PassNoise>,
) -> Vec<Option<Response>> {
    let none = vec![None; y.ncols()];
    if x.nrows() != y.nrows() || u.shape() != y.shape() || measured.len() != y.ncols() {
        return none;
    }
    let paired = in_pairs && x.nrows().is_multiple_of(2);
    let passes = passes.filter(|p| p.variance.len() == y.ncols() && p.dof > 0);
    let (x, y, u) = if paired {
        half_differences(x, y, u)
    } else {
        (x.clone(), y.clone(), u.clone())
    };
    let Some(q) = design_basis(&x) else {
        return none;
    };
    let (rows, columns) = q.shape();
    (0..y.ncols())
        .map(|j| {
            if !measured[j] {
                return None;
            }
            let yj = y.column(j);
            let scale = yj.amax();
            if !(scale.is_finite() && scale > 0.0) {
                return None;
            }
            let yj = yj / scale;
            let scale2 = scale * scale;
            let row = if paired { 0.5 } else { 1.0 };
            Some(test(
                Sums {
                    explained: (q.transpose() * &yj).norm_squared(),
                    total: yj.norm_squared(),
                    columns,
                    dof: rows - columns,
                },
                u.column(j).mean() / scale2,
                passes.map(|p| (p.variance[j] * row / scale2, p.dof)),
            ))
        })
        .collect()
}

/// `+-` pairs (rows `2i`, `2i + 1`) read by their half-differences: `(x(+d) - x(-d)) / 2`
/// against `(y(+d) - y(-d)) / 2`, each row's variance `(u(+d) + u(-d)) / 4`.
pub(crate) fn half_differences(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    u: &DMatrix<f64>,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let half = |m: &DMatrix<f64>, sign: f64, factor: f64| {
        DMatrix::from_fn(m.nrows() / 2, m.ncols(), |i, j| {
            factor * (m[(2 * i, j)] + sign * m[(2 * i + 1, j)])
        })
    };
    (half(x, -1.0, 0.5), half(y, -1.0, 0.5), half(u, 1.0, 0.25))
}

/// An orthonormal basis (rows x columns) of the span of the perturbations `x`, its columns
/// scaled first (perturbations of 1e-9 and of 1 rad may meet in one design); None with fewer
/// rows than columns, no column, or a column that is zero or not finite.
pub(crate) fn design_basis(x: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (rows, columns) = x.shape();
    if rows < columns || columns == 0 {
        return None;
    }
    let scales: Vec<f64> = x.column_iter().map(|c| c.amax()).collect();
    if scales.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return None;
    }
    let mut xs = x.clone();
    for (mut c, s) in xs.column_iter_mut().zip(&scales) {
        c /= *s;
    }
    Some(xs.qr().q())
}

/// One joint's regression of its torque changes on the perturbations, as the test reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Sums {
    /// The squared norm of the changes' projection on the perturbations.
    pub explained: f64,
    /// The changes' squared norm.
    pub total: f64,
    /// The perturbed joints (the regression's columns) and the residual degrees of freedom.
    pub columns: usize,
    pub dof: usize,
}

/// The F test of one joint's [`Sums`]: the noise is the residuals' mean square where there are
/// residual degrees of freedom, otherwise `samples` (the mean variance of a row from the
/// samples' noise) or, where `pass` (a row's variance from pass to pass, with its degrees of
/// freedom) exceeds it beyond chance (their ratio's F test at [`FALSE_ALARM`]), `pass`. All in
/// one unit.
pub(crate) fn test(sums: Sums, samples: f64, pass: Option<(f64, usize)>) -> Response {
    let Sums {
        explained,
        total,
        columns,
        dof,
    } = sums;
    let (noise, d2) = if dof > 0 {
        ((total - explained).max(0.0) / dof as f64, dof as f64)
    } else {
        // the passes' noise where the readings scatter beyond their samples' noise
        let beyond = |(variance, dof): (f64, usize)| {
            let ratio = (variance / samples).min(1e300);
            ratio > 1.0
                && dof > 0
                && crate::student_t::f_upper_tail(ratio, dof as f64, KNOWN_NOISE_DOF) < FALSE_ALARM
        };
        match pass {
            Some((variance, dof)) if beyond((variance, dof)) => (variance, dof as f64),
            _ => (samples, KNOWN_NOISE_DOF),
        }
    };
    let f = (explained / columns as f64) / noise;
    let p = if f.is_nan() {
        1.0
    } else {
        crate::student_t::f_upper_tail(f.min(1e300), columns as f64, d2)
    };
    Response { f, p }
}

/// The warning for an experiment none of whose joints' torques responded to its perturbations
/// beyond their noise (smallest `p` times the joints tested above [`FALSE_ALARM`]), with how
/// much larger the perturbations, or how many more crossings, would make the strongest
/// response clear (an F of 10 times the threshold's). None when one joint responds, or when
/// none could be tested.
pub fn unresolved_warning(kind: ExperimentKind, found: &[Option<Response>]) -> Option<String> {
    if resolved(found)? {
        return None;
    }
    let tested: Vec<Response> = found.iter().flatten().copied().collect();
    let smallest = tested.iter().map(|r| r.p).fold(1.0, f64::min);
    let strongest = tested
        .iter()
        .map(|r| r.f)
        .filter(|f| f.is_finite())
        .fold(0.0, f64::max);
    let estimate = kind.estimate_name();
    let variable = kind.perturbation_name();
    let slow = if kind == ExperimentKind::H {
        " H* is small at slow operating points without viscous friction (zero at rest), and this may be its measurement;"
    } else {
        ""
    };
    // the F statistic grows with the square of the perturbations and with the crossings
    let larger = if strongest > 0.0 {
        let factor = (40.0 / strongest).sqrt().max(2.0);
        format!(
            "perturbations ({variable}) about {} times larger, or {} times as many crossings, would make it clear if it is not zero",
            shown_factor(factor),
            shown_factor(factor * factor)
        )
    } else {
        format!(
            "larger perturbations ({variable}) or more crossings would show it if it is not zero"
        )
    };
    Some(format!(
        "experiment '{}': no joint's torque responded to the perturbations beyond its noise (the strongest explains {strongest:.1} times the residuals' mean square, which noise alone reaches {:.0} % of the time), so {estimate} is not resolved: its values are within their noise of zero;{slow} otherwise the perturbations are too small for the torque sensor, or the torque channels do not follow the robot: {larger}",
        kind.name(),
        (100.0 * smallest).min(100.0)
    ))
}

/// Whether one joint's torque responded: its `p` times the joints tested at most
/// [`FALSE_ALARM`] (Bonferroni). None when no joint could be tested.
pub fn resolved(found: &[Option<Response>]) -> Option<bool> {
    let tested = found.iter().flatten().count();
    let smallest = found.iter().flatten().map(|r| r.p).fold(1.0, f64::min);
    (tested > 0).then_some(smallest * tested as f64 <= FALSE_ALARM)
}

/// The warning for `experiment` when none of its torques responded: [`responses`] of its
/// regression (`x`, `y`, `u` as there, one row per crossing read), read by `+-` pairs when it
/// was planned in pairs and every planned crossing was read, leaving out the channels that read
/// one value throughout (`flat_torque`), with the noise from pass to pass of `passes` where the
/// regression has no residual degree of freedom, and [`unresolved_warning`].
pub(super) fn experiment_warning(
    experiment: &Experiment,
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    u: &DMatrix<f64>,
    flat_torque: &[Option<f64>],
    passes: Option<&PassNoise>,
) -> Option<String> {
    let measured: Vec<bool> = flat_torque.iter().map(Option::is_none).collect();
    let in_pairs = experiment.in_pairs() && experiment.deltas.nrows() == x.nrows();
    unresolved_warning(
        experiment.kind,
        &responses(x, y, u, in_pairs, &measured, passes),
    )
}

/// A factor: one decimal below 10, whole below 100, with an exponent above (the planner's
/// prediction shows its factors so too).
pub(crate) fn shown_factor(f: f64) -> String {
    if f < 10.0 {
        format!("{f:.1}")
    } else if f < 100.0 {
        format!("{f:.0}")
    } else {
        format!("{f:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn design(k: usize, n: usize, seed: u64) -> DMatrix<f64> {
        crate::local::perturbation::perturbations(
            crate::local::Design::Random,
            k,
            &vec![1.0; n],
            true,
            seed,
        )
        .unwrap()
    }

    /// Seeded Gaussian noise of standard deviation `size`.
    fn noise(k: usize, n: usize, size: f64, seed: u64) -> DMatrix<f64> {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        DMatrix::from_fn(k, n, |_, _| {
            size * <StandardNormal as Distribution<f64>>::sample(&StandardNormal, &mut rng)
        })
    }

    /// Without residual degrees of freedom, noise from pass to pass (readings that scatter
    /// 0.01 where their samples say 0.001) is the noise once the passes show it; passes that
    /// scatter as their samples say leave the samples' noise (and its many degrees of freedom).
    #[test]
    fn the_passes_noise_is_taken_where_the_readings_scatter_beyond_their_samples() {
        let (k, n) = (6, 3);
        let x = design(k, n, 3);
        let measured = vec![true; n];
        let u = DMatrix::from_element(k, n, 1e-6);
        let e = noise(k, n, 0.01, 4);
        let readings = |size: f64, seed: u64| -> Vec<Vec<f64>> {
            let r = noise(12, n, size, seed);
            r.row_iter()
                .map(|row| row.iter().copied().collect())
                .collect()
        };
        let of = |r: &[Vec<f64>]| PassNoise::of(r.iter().map(Vec::as_slice));
        let slow = of(&readings(0.01, 5)).unwrap();
        assert_eq!(slow.dof, 11);
        let alone = responses(&x, &e, &u, true, &measured, None);
        assert_eq!(resolved(&alone), Some(true), "{alone:?}");
        let named = responses(&x, &e, &u, true, &measured, Some(&slow));
        assert_eq!(resolved(&named), Some(false), "{named:?}");
        // a response well beyond the passes' noise is still found against it
        let b = DMatrix::from_diagonal_element(n, n, 1.0);
        let found = responses(&x, &(&x * &b + &e), &u, true, &measured, Some(&slow));
        assert_eq!(resolved(&found), Some(true), "{found:?}");
        // passes as noisy as their samples: the samples' test, unchanged
        let white = of(&readings(0.001, 6)).unwrap();
        assert_eq!(responses(&x, &e, &u, true, &measured, Some(&white)), alone);
        // fewer than two readings hold no scatter
        assert_eq!(of(&readings(0.01, 7)[..1]), None);
        assert_eq!(of(&[vec![1.0, 2.0], vec![1.0]]), None);
    }

    #[test]
    fn a_response_beyond_the_noise_is_found_and_noise_alone_is_named() {
        let (k, n) = (24, 3);
        let x = design(k, n, 1);
        let b = DMatrix::from_row_slice(3, 3, &[1.0, 0.2, 0.0, 0.1, 2.0, 0.3, 0.0, 0.4, 1.5]);
        let measured = vec![true; n];
        let e = noise(k, n, 0.01, 2);
        let u = DMatrix::from_element(k, n, 1e-4);
        let clear = responses(&x, &(&x * b.transpose() + &e), &u, false, &measured, None);
        assert!(clear.iter().all(|r| r.unwrap().p < 1e-10), "{clear:?}");
        assert_eq!(unresolved_warning(ExperimentKind::GDynamic, &clear), None);
        // the same response 1e4 times smaller than the noise
        let lost = responses(
            &x,
            &(&x * b.transpose() * 1e-6 + &e),
            &u,
            false,
            &measured,
            None,
        );
        let w = unresolved_warning(ExperimentKind::GDynamic, &lost).expect("noise alone");
        assert!(
            w.starts_with("experiment 'G': no joint's torque responded"),
            "{w}"
        );
        assert!(w.contains("so G* is not resolved"), "{w}");
        assert!(w.contains("perturbations (dq) about"), "{w}");
        assert!(!w.contains("slow operating points"), "{w}");
        // a flat channel is not tested; nothing tested, nothing said
        let none = responses(&x, &e, &u, false, &[false; 3], None);
        assert!(none.iter().all(Option::is_none));
        assert_eq!(unresolved_warning(ExperimentKind::D, &none), None);
        // without residual degrees of freedom the samples' noise is the noise
        let (x3, e3, u3) = (
            x.rows(0, 3).into_owned(),
            e.rows(0, 3).into_owned(),
            u.rows(0, 3).into_owned(),
        );
        let alone = responses(&x3, &e3, &u3, false, &measured, None);
        assert!(
            unresolved_warning(ExperimentKind::D, &alone).is_some(),
            "{alone:?}"
        );
        let moved = responses(
            &x3,
            &(&x3 * b.transpose() + &e3),
            &u3,
            false,
            &measured,
            None,
        );
        assert_eq!(
            unresolved_warning(ExperimentKind::D, &moved),
            None,
            "{moved:?}"
        );
        // shapes that do not fit are not tested
        assert!(responses(&x, &e, &u3, false, &measured, None)
            .iter()
            .all(Option::is_none));
    }

    #[test]
    fn pairs_are_read_by_their_half_differences() {
        // a small exact linear response under a large even-order term that the pairs cancel
        let (k, n) = (24, 3);
        let x = design(k, n, 3);
        let b = DMatrix::from_diagonal_element(3, 3, 0.01);
        let e = noise(k, n, 1e-9, 4);
        let mut y = &x * b.transpose() + e;
        for i in 0..k {
            for j in 0..n {
                y[(i, j)] += 5.0 * x.row(i).norm_squared() * (1.0 + j as f64);
            }
        }
        let measured = vec![true; n];
        let u = DMatrix::from_element(k, n, 1e-18);
        let full = responses(&x, &y, &u, false, &measured, None);
        assert!(
            unresolved_warning(ExperimentKind::H, &full).is_some(),
            "{full:?}"
        );
        let pairs = responses(&x, &y, &u, true, &measured, None);
        assert!(pairs.iter().all(|r| r.unwrap().p < 1e-10), "{pairs:?}");
        assert_eq!(unresolved_warning(ExperimentKind::H, &pairs), None);
    }

    #[test]
    fn h_at_slow_points_says_it_may_be_its_measurement() {
        let (k, n) = (16, 2);
        let x = design(k, n, 5);
        let e = noise(k, n, 0.1, 6);
        let u = DMatrix::from_element(k, n, 0.01);
        let w = unresolved_warning(
            ExperimentKind::H,
            &responses(&x, &e, &u, true, &[true; 2], None),
        )
        .unwrap();
        assert!(w.contains("H* is small at slow operating points"), "{w}");
        assert!(w.contains("perturbations (dqd)"), "{w}");
    }
}
