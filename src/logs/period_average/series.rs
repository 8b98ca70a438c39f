//! Fourier series on one period's grid: projection, the series and its derivatives, the
//! energies of their differences (Parseval), and coefficient-wise medians.

pub(super) fn median_of(x: &[f64]) -> f64 {
    median_of_mut(&mut x.to_vec())
}

pub(super) fn median_of_mut(x: &mut [f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    x.sort_by(f64::total_cmp);
    let k = x.len();
    if k % 2 == 1 {
        x[k / 2]
    } else {
        0.5 * (x[k / 2 - 1] + x[k / 2])
    }
}

/// The coefficient-wise median of the periods' coefficients.
pub(super) fn median_coefficients(per: &[&[f64]]) -> Vec<f64> {
    (0..per[0].len())
        .map(|c| median_of_mut(&mut per.iter().map(|x| x[c]).collect::<Vec<f64>>()))
        .collect()
}

/// The mean square over a period of the series `x - y` (coefficients `[a_0, a_1, b_1, ...]`),
/// by Parseval.
pub(super) fn energy(x: &[f64], y: &[f64]) -> f64 {
    weighted_energy(x, y, &|_| 1.0)
}

/// The mean square over a period of the series `x` with harmonic `k`'s share weighted by
/// `weight(k)` (its power; [`weighted_energy`] against nothing).
pub(super) fn weighted_power(x: &[f64], weight: &dyn Fn(usize) -> f64) -> f64 {
    let mut e = weight(0) * x[0].powi(2);
    for k in 1..=(x.len() - 1) / 2 {
        e += 0.5 * weight(k) * (x[2 * k - 1].powi(2) + x[2 * k].powi(2));
    }
    e
}

/// [`energy`] with harmonic `k`'s share weighted by `weight(k)`.
pub(super) fn weighted_energy(x: &[f64], y: &[f64], weight: &dyn Fn(usize) -> f64) -> f64 {
    let mut e = weight(0) * (x[0] - y[0]).powi(2);
    for k in 1..=(x.len() - 1) / 2 {
        let (da, db) = (x[2 * k - 1] - y[2 * k - 1], x[2 * k] - y[2 * k]);
        e += 0.5 * weight(k) * (da * da + db * db);
    }
    e
}

/// The cosines and sines of one period's grid of `m` points.
pub(super) struct Table {
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl Table {
    pub(super) fn new(m: usize) -> Self {
        let (sin, cos) = (0..m)
            .map(|i| (std::f64::consts::TAU * i as f64 / m as f64).sin_cos())
            .unzip();
        Self { cos, sin }
    }

    /// The Fourier coefficients `[a_0, a_1, b_1, ..., a_h, b_h]` of one period's samples `x`
    /// (`x(i) = a_0 + sum_k a_k cos(2 pi k i / m) + b_k sin(2 pi k i / m)`), exact for a
    /// series of at most `h < m / 2` harmonics.
    pub(super) fn project(&self, x: &[f64], h: usize) -> Vec<f64> {
        let m = x.len();
        let mut c = Vec::with_capacity(2 * h + 1);
        c.push(x.iter().sum::<f64>() / m as f64);
        for k in 1..=h {
            let (mut a, mut b, mut idx) = (0.0, 0.0, 0usize);
            for &xi in x {
                a += xi * self.cos[idx];
                b += xi * self.sin[idx];
                idx += k;
                if idx >= m {
                    idx -= m;
                }
            }
            c.push(2.0 * a / m as f64);
            c.push(2.0 * b / m as f64);
        }
        c
    }

    /// The series of coefficients `c` (its first `h` harmonics) on the grid.
    pub(super) fn values(&self, c: &[f64], h: usize) -> Vec<f64> {
        let m = self.cos.len();
        let mut x = vec![c[0]; m];
        for k in 1..=h {
            let (a, b) = (c[2 * k - 1], c[2 * k]);
            let mut idx = 0usize;
            for xi in x.iter_mut() {
                *xi += a * self.cos[idx] + b * self.sin[idx];
                idx += k;
                if idx >= m {
                    idx -= m;
                }
            }
        }
        x
    }

    /// The series of coefficients `c` (its first `h` harmonics) on the grid, with its first
    /// and second derivatives in time for the base pulsation `w` (rad/s).
    pub(super) fn series(&self, c: &[f64], h: usize, w: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let m = self.cos.len();
        let (mut x, mut v, mut acc) = (vec![c[0]; m], vec![0.0; m], vec![0.0; m]);
        for k in 1..=h {
            let (a, b) = (c[2 * k - 1], c[2 * k]);
            let wk = w * k as f64;
            let mut idx = 0usize;
            for i in 0..m {
                let (co, si) = (self.cos[idx], self.sin[idx]);
                x[i] += a * co + b * si;
                v[i] += wk * (b * co - a * si);
                acc[i] -= wk * wk * (a * co + b * si);
                idx += k;
                if idx >= m {
                    idx -= m;
                }
            }
        }
        (x, v, acc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_and_series_are_exact_on_the_grid() {
        let m = 100;
        let table = Table::new(m);
        let w = std::f64::consts::TAU / 2.0;
        let f = |t: f64| 0.3 + 0.5 * (w * t).cos() - 0.2 * (3.0 * w * t).sin();
        let x: Vec<f64> = (0..m).map(|i| f(2.0 * i as f64 / m as f64)).collect();
        let c = table.project(&x, 5);
        let expected = [0.3, 0.5, 0.0, 0.0, 0.0, 0.0, -0.2, 0.0, 0.0, 0.0, 0.0];
        for (a, b) in c.iter().zip(expected) {
            assert!((a - b).abs() < 1e-14, "{c:?}");
        }
        let (y, v, acc) = table.series(&c, 5, w);
        for i in 0..m {
            let t = 2.0 * i as f64 / m as f64;
            let h = 1e-5;
            assert!((y[i] - f(t)).abs() < 1e-13);
            assert!((v[i] - (f(t + h) - f(t - h)) / (2.0 * h)).abs() < 1e-8);
            assert!((acc[i] - (f(t + h) - 2.0 * f(t) + f(t - h)) / (h * h)).abs() < 1e-4);
        }
        // Parseval: the mean square on the grid
        let ms = x.iter().map(|v| v * v).sum::<f64>() / m as f64;
        assert!((energy(&c, &[0.0; 11]) - ms).abs() < 1e-14);
    }
}
