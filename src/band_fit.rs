//! Polynomials that pass within a band of readings: a set-membership fit for readings rounded
//! to a grid (docs/method.md, section 4, coarse encoders).
//!
//! A position logged in whole encoder counts `s` errs by up to `s / 2` in every sample, and
//! when the encoder has no noise beyond its rounding the error is a function of the position,
//! not random: a joint that moves by a few counts in a window reads a staircase, and a least-
//! squares quadratic through it can be off in curvature by several times the standard error the
//! staircase's scatter suggests (on the A465 at Table 2 with 4,096 counts a revolution: 0.55
//! rad/s^2 RMS where the scatter said 0.08). What the readings do say for certain is that the
//! true position was within `s / 2` of every one of them. Over the polynomials `p` of a degree
//! with `|p(u_i) - y_i| <= delta` for every reading, each coefficient ranges over an interval
//! ([`coefficient_ranges`]): its midpoint is the estimate, its half-width the bound of its
//! error.
//!
//! Each end of an interval is a linear program in the `m = degree + 1` coefficients with `2 n`
//! constraints. It is solved here in its dual, `min sum_i lambda_i (y_i + delta) + mu_i (delta -
//! y_i)` over `lambda, mu >= 0` with `sum_i (lambda_i - mu_i) a_i = c` (`a_i = (1, u_i, u_i^2,
//! ...)`, `c` the coefficient's unit vector), by the revised simplex method with an `m x m`
//! basis: `m` equality rows, so each step costs `O(n m)`. The dual is always feasible (a basis
//! of `m` readings at distinct `u`), and it is unbounded exactly when no polynomial stays in the
//! band (the primal is infeasible): noise beyond the rounding, or motion that is no polynomial
//! of the degree.

#[cfg(test)]
use nalgebra::{DMatrix, DVector};

/// The most coefficients (`degree + 1`) [`coefficient_ranges`] takes.
pub const MAX_COEFFICIENTS: usize = 4;

/// Relative tolerance of the simplex method's optimality and ratio tests.
const TOLERANCE: f64 = 1e-10;

/// The most simplex steps one end of a range may take; beyond it the fit gives up (None).
/// Windows of 100 to 100,000 rounded readings of a quadratic settle within 15 steps (each
/// costs `O(n m)`), so this bounds the work on hostile data without touching real data.
pub const MAX_STEPS: usize = 500;

/// For each coefficient `c_d` (`d = 0..=degree`) of the polynomials `p(u) = sum_d c_d u^d`
/// that pass within `delta` of every reading (`|p(u_i) - y_i| <= delta` for all `i`), its
/// range `[lowest, highest]` over them.
///
/// `u` are the readings' abscissae (best scaled to `[-1, 1]`: the basis is the monomials),
/// `y` their values, both of length n; `delta > 0` is the band's half-width, in the units of
/// `y` (half a step for readings rounded to whole steps). Returns None when no polynomial of
/// the degree stays in the band (noise beyond the rounding, or motion no such polynomial
/// follows), when fewer than `degree + 1` distinct finite `u` are given, when any input is not
/// finite, when `degree + 1` exceeds [`MAX_COEFFICIENTS`] or the lengths differ, and when the
/// simplex method does not settle within [`MAX_STEPS`] steps (degenerate data it cannot
/// resolve): a caller falls back to another estimate, never to a guess.
pub fn coefficient_ranges(
    u: &[f64],
    y: &[f64],
    delta: f64,
    degree: usize,
) -> Option<Vec<[f64; 2]>> {
    let m = degree + 1;
    let n = u.len();
    if m > MAX_COEFFICIENTS
        || y.len() != n
        || !(delta.is_finite() && delta > 0.0)
        || u.iter().chain(y).any(|v| !v.is_finite())
    {
        return None;
    }
    match m {
        1 => ranges::<1>(u, y, delta),
        2 => ranges::<2>(u, y, delta),
        3 => ranges::<3>(u, y, delta),
        _ => ranges::<4>(u, y, delta),
    }
}

/// [`coefficient_ranges`] for `M` coefficients, on checked inputs.
fn ranges<const M: usize>(u: &[f64], y: &[f64], delta: f64) -> Option<Vec<[f64; 2]>> {
    let start = initial_rows(u, M)?;
    let rows: Vec<[f64; M]> = u
        .iter()
        .map(|&x| std::array::from_fn(|d| x.powi(d as i32)))
        .collect();
    (0..M)
        .map(|d| {
            let mut c = [0.0; M];
            c[d] = 1.0;
            let highest = maximise(&rows, y, delta, &c, &start)?;
            c[d] = -1.0;
            let lowest = -maximise(&rows, y, delta, &c, &start)?;
            // the two ends of one feasible set: lowest > highest only by rounding
            Some([lowest.min(highest), highest.max(lowest)])
        })
        .collect()
}

fn dot<const M: usize>(a: &[f64; M], b: &[f64; M]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves `a x = b` (`a[r][k]`: row r, column k) by Gaussian elimination with partial
/// pivoting; None when `a` is singular to working precision.
fn solve<const M: usize>(mut a: [[f64; M]; M], mut b: [f64; M]) -> Option<[f64; M]> {
    let norm = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..M {
        let pivot = (k..M).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[pivot][k].abs() <= 1e-14 * norm || a[pivot][k].is_nan() {
            return None;
        }
        a.swap(k, pivot);
        b.swap(k, pivot);
        let (top, below) = a.split_at_mut(k + 1);
        let row_k = &top[k];
        for (i, row) in below.iter_mut().enumerate() {
            let f = row[k] / row_k[k];
            for (x, r) in row.iter_mut().zip(row_k).skip(k) {
                *x -= f * r;
            }
            b[k + 1 + i] -= f * b[k];
        }
    }
    let mut x = [0.0; M];
    for k in (0..M).rev() {
        let s: f64 = (k + 1..M).map(|l| a[k][l] * x[l]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Indices of `m` readings at distinct abscissae spread over the range of `u` (a well
/// conditioned basis to start from); None with fewer than `m` distinct abscissae.
fn initial_rows(u: &[f64], m: usize) -> Option<Vec<usize>> {
    let mut order: Vec<usize> = (0..u.len()).collect();
    order.sort_by(|&a, &b| u[a].total_cmp(&u[b]));
    order.dedup_by(|a, b| u[*a] == u[*b]);
    if order.len() < m {
        return None;
    }
    if m == 1 {
        return Some(vec![order[order.len() / 2]]);
    }
    Some(
        (0..m)
            .map(|k| order[k * (order.len() - 1) / (m - 1)])
            .collect(),
    )
}

/// A column of the dual: reading `i` with sign +1 (`lambda_i`, the band's upper side) or -1
/// (`mu_i`, its lower side).
#[derive(Clone, Copy, PartialEq, Debug)]
struct Column {
    reading: usize,
    sign: f64,
}

/// The maximum of `c . p` over the coefficients `p` whose polynomial stays within `delta` of
/// every reading (`rows[i]` the monomials at `u_i`); None when there are none (the dual
/// unbounded) or the simplex method does not settle within [`MAX_STEPS`].
fn maximise<const M: usize>(
    rows: &[[f64; M]],
    y: &[f64],
    delta: f64,
    c: &[f64; M],
    start: &[usize],
) -> Option<f64> {
    let cost = |col: Column| delta + col.sign * y[col.reading];
    // B (column k the basic column k: sign times the monomials of its reading) and B^T
    let basis_matrix = |basis: &[Column; M]| -> [[f64; M]; M] {
        std::array::from_fn(|r| std::array::from_fn(|k| basis[k].sign * rows[basis[k].reading][r]))
    };
    let transpose = |a: [[f64; M]; M]| -> [[f64; M]; M] {
        std::array::from_fn(|r| std::array::from_fn(|k| a[k][r]))
    };
    // a feasible start: c in the basis of the starting readings, each with the sign that makes
    // its weight non-negative
    let mut basis: [Column; M] = std::array::from_fn(|k| Column {
        reading: start[k],
        sign: 1.0,
    });
    let w0 = solve(basis_matrix(&basis), *c)?;
    for (col, w) in basis.iter_mut().zip(w0) {
        if w < 0.0 {
            col.sign = -1.0;
        }
    }
    let scale = y.iter().fold(delta, |a, v| a.max(v.abs()));
    let tolerance = TOLERANCE * scale;
    let mut stalled = 0usize;
    let mut previous = f64::INFINITY;
    for _ in 0..MAX_STEPS {
        let b = basis_matrix(&basis);
        let x_b = solve(b, *c)?;
        let cost_b: [f64; M] = std::array::from_fn(|k| cost(basis[k]));
        // the dual's prices: the candidate polynomial's coefficients
        let p = solve(transpose(b), cost_b)?;
        let objective = dot(&cost_b, &x_b);
        if objective < previous - tolerance {
            stalled = 0;
        } else {
            stalled += 1;
        }
        previous = previous.min(objective);
        // the entering column: the most violated side of the band (Dantzig), or after a run
        // of steps without progress the first violated one (Bland's rule against cycling)
        let bland = stalled > 2 * M;
        let mut entering: Option<(Column, f64)> = None;
        for (i, row) in rows.iter().enumerate() {
            // the candidate's residual: a reduced cost below 0 is a reading outside the band
            let residual = dot(row, &p) - y[i];
            for (sign, reduced) in [(1.0, delta - residual), (-1.0, delta + residual)] {
                if reduced < -tolerance && entering.is_none_or(|(_, r)| reduced < r) {
                    let col = Column { reading: i, sign };
                    if !basis.contains(&col) {
                        entering = Some((col, reduced));
                    }
                }
            }
            if bland && entering.is_some() {
                break;
            }
        }
        let Some((col, _)) = entering else {
            return Some(objective);
        };
        let direction = solve(b, rows[col.reading].map(|v| col.sign * v))?;
        let leaving = (0..M)
            .filter(|&k| direction[k] > TOLERANCE)
            .min_by(|&a, &b| {
                (x_b[a].max(0.0) / direction[a]).total_cmp(&(x_b[b].max(0.0) / direction[b]))
            });
        // no ratio bounds the step: the dual is unbounded, no polynomial stays in the band
        basis[leaving?] = col;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every vertex of the feasible set: for each choice of `m` band sides at distinct
    /// readings, the polynomial through them, kept when it stays in the band.
    fn vertices(u: &[f64], y: &[f64], delta: f64, m: usize) -> Vec<DVector<f64>> {
        let sides: Vec<(usize, f64)> = (0..u.len()).flat_map(|i| [(i, 1.0), (i, -1.0)]).collect();
        let mut out = vec![];
        let mut pick = vec![0usize; m];
        fn next(pick: &mut [usize], len: usize) -> bool {
            let m = pick.len();
            for k in (0..m).rev() {
                if pick[k] < len - (m - k) {
                    pick[k] += 1;
                    for l in k + 1..m {
                        pick[l] = pick[l - 1] + 1;
                    }
                    return true;
                }
            }
            false
        }
        for (k, p) in pick.iter_mut().enumerate() {
            *p = k;
        }
        loop {
            let a = DMatrix::from_fn(m, m, |r, d| u[sides[pick[r]].0].powi(d as i32));
            let b = DVector::from_fn(m, |r, _| y[sides[pick[r]].0] + sides[pick[r]].1 * delta);
            if let Some(p) = a.lu().solve(&b) {
                let inside = (0..u.len()).all(|i| {
                    let v: f64 = (0..m).map(|d| p[d] * u[i].powi(d as i32)).sum();
                    (v - y[i]).abs() <= delta * (1.0 + 1e-9)
                });
                if inside && p.iter().all(|v| v.is_finite()) {
                    out.push(p);
                }
            }
            if !next(&mut pick, sides.len()) {
                break;
            }
        }
        out
    }

    #[test]
    fn ranges_are_the_extremes_over_the_vertices() {
        // rounded quadratics (and lines, cubics) at a few readings: the ranges equal the
        // extremes over every vertex of the feasible set, found by enumeration
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for trial in 0..60 {
            let degree = 1 + trial % 3;
            let m = degree + 1;
            let n = 6 + trial % 4;
            let u: Vec<f64> = (0..n)
                .map(|i| -1.0 + 2.0 * i as f64 / (n - 1) as f64)
                .collect();
            let c: Vec<f64> = (0..m).map(|_| 6.0 * rand()).collect();
            let y: Vec<f64> = u
                .iter()
                .map(|&x| (0..m).map(|d| c[d] * x.powi(d as i32)).sum::<f64>().round())
                .collect();
            let ranges = coefficient_ranges(&u, &y, 0.5, degree).expect("feasible: the truth is");
            let v = vertices(&u, &y, 0.5, m);
            assert!(!v.is_empty());
            for d in 0..m {
                let lo = v.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min);
                let hi = v.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    (ranges[d][0] - lo).abs() < 1e-8,
                    "trial {trial} d {d}: {:?} vs {lo}",
                    ranges[d]
                );
                assert!(
                    (ranges[d][1] - hi).abs() < 1e-8,
                    "trial {trial} d {d}: {:?} vs {hi}",
                    ranges[d]
                );
                // the rounded polynomial's own coefficients are inside
                assert!(ranges[d][0] - 1e-9 <= c[d] && c[d] <= ranges[d][1] + 1e-9);
            }
        }
    }

    #[test]
    fn one_level_bounds_the_curvature_by_twice_the_band() {
        // readings that all round to one level: |c0 + c1 u + c2 u^2| <= delta on [-1, 1]
        // (with u = -1, 0, 1 among the readings) allows c2 up to 2 delta (the Chebyshev
        // polynomial 2 delta u^2 - delta), c1 up to delta and c0 up to delta
        let u: Vec<f64> = (0..101).map(|i| -1.0 + i as f64 / 50.0).collect();
        let y = vec![3.0; 101];
        let r = coefficient_ranges(&u, &y, 0.5, 2).unwrap();
        assert!(
            (r[2][0] + 1.0).abs() < 1e-9 && (r[2][1] - 1.0).abs() < 1e-9,
            "{r:?}"
        );
        assert!(
            (r[1][0] + 0.5).abs() < 1e-9 && (r[1][1] - 0.5).abs() < 1e-9,
            "{r:?}"
        );
        assert!(
            (r[0][0] - 2.5).abs() < 1e-9 && (r[0][1] - 3.5).abs() < 1e-9,
            "{r:?}"
        );
    }

    #[test]
    fn no_polynomial_in_the_band_is_none() {
        // a reading two steps off a line: no line stays within half a step of all
        let u = [-1.0, -0.5, 0.0, 0.5, 1.0];
        let y = [0.0, 0.0, 2.0, 0.0, 0.0];
        assert_eq!(coefficient_ranges(&u, &y, 0.5, 1), None);
        // fewer distinct abscissae than coefficients, non-finite input, bad band
        assert_eq!(
            coefficient_ranges(&[0.0, 0.0, 1.0], &[0.0; 3], 0.5, 2),
            None
        );
        assert_eq!(
            coefficient_ranges(&[0.0, f64::NAN, 1.0], &[0.0; 3], 0.5, 1),
            None
        );
        assert_eq!(coefficient_ranges(&u, &[0.0; 5], 0.0, 1), None);
        assert_eq!(coefficient_ranges(&u, &[0.0; 4], 0.5, 1), None);
        assert_eq!(coefficient_ranges(&u, &[0.0; 5], 0.5, 4), None);
    }

    #[test]
    fn many_readings_settle() {
        // a window of 2,001 readings of a slowly curving staircase
        let u: Vec<f64> = (0..2001).map(|i| -1.0 + i as f64 / 1000.0).collect();
        let y: Vec<f64> = u
            .iter()
            .map(|&x| (7.3 * x + 2.1 * x * x + 0.4).round())
            .collect();
        let r = coefficient_ranges(&u, &y, 0.5, 2).unwrap();
        assert!(
            r[2][0] <= 2.1 && 2.1 <= r[2][1] && r[2][1] - r[2][0] < 0.1,
            "{r:?}"
        );
    }
}
