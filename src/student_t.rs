//! Student's t distribution: the threshold a difference of estimates must pass when its
//! standard error is itself estimated from few residual degrees of freedom; and the F
//! distribution's tail, for a regression's sum of squares against its residuals'; and the
//! chi-square distribution's, for a fit's residuals against a noise measured beforehand.

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7, 9 terms: about 15 digits).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // reflection
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised incomplete beta function `I_x(a, b)` (continued fraction, modified Lentz).
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(1.0 - x, b, a);
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp() / a;
    let tiny = 1e-300;
    let (mut c, mut d) = (1.0, 1.0 - (a + b) * x / (a + 1.0));
    d = 1.0 / if d.abs() < tiny { tiny } else { d };
    let mut f = d;
    for m in 1..500 {
        let m = m as f64;
        for numerator in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 + numerator * d;
            d = 1.0 / if d.abs() < tiny { tiny } else { d };
            c = 1.0 + numerator / c;
            if c.abs() < tiny {
                c = tiny;
            }
            f *= c * d;
        }
        if (c * d - 1.0).abs() < 1e-15 {
            break;
        }
    }
    front * f
}

/// `P(T > t)` for Student's t with `nu` degrees of freedom, `t >= 0`.
pub fn upper_tail(t: f64, nu: f64) -> f64 {
    0.5 * incomplete_beta(nu / (nu + t * t), 0.5 * nu, 0.5)
}

/// The `t` with `P(T > t) = p` for Student's t with `nu > 0` degrees of freedom, `0 < p <
/// 0.5` (bisection to 1e-10 relative; at most 1e6).
pub fn upper_quantile(p: f64, nu: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1e6f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if upper_tail(mid, nu) > p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-10 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// `P(F > f)` for the F distribution with `d1` and `d2` degrees of freedom, `f >= 0`: the
/// chance that a regression on `d1` columns of pure noise explains `f` times its residuals'
/// mean square (`d2` residual degrees of freedom) or more.
pub fn f_upper_tail(f: f64, d1: f64, d2: f64) -> f64 {
    incomplete_beta(d2 / (d2 + d1 * f), 0.5 * d2, 0.5 * d1)
}

/// The regularised upper incomplete gamma function `Q(a, x) = Gamma(a, x) / Gamma(a)` for
/// `a > 0`, `x >= 0` (the series below `a + 1`, the continued fraction beyond, modified Lentz;
/// about 14 digits).
fn upper_incomplete_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (a * x.ln() - x - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // P(a, x) = x^a e^-x / Gamma(a + 1) sum_n x^n / ((a + 1) ... (a + n))
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        return (1.0 - front * sum).max(0.0);
    }
    let tiny = 1e-300;
    let mut b = x + 1.0 - a;
    let (mut c, mut d) = (1.0 / tiny, 1.0 / b);
    let mut f = d;
    for i in 1..10_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        d = 1.0 / if d.abs() < tiny { tiny } else { d };
        c = b + an / c;
        if c.abs() < tiny {
            c = tiny;
        }
        f *= c * d;
        if (c * d - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (front * f).clamp(0.0, 1.0)
}

/// `P(X > x)` for the chi-square distribution with `k > 0` degrees of freedom, `x >= 0`: the
/// chance that `k` independent unit normal values have a sum of squares of `x` or more.
pub fn chi_square_upper_tail(x: f64, k: f64) -> f64 {
    upper_incomplete_gamma(0.5 * k, 0.5 * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against printed tables (e.g. Abramowitz & Stegun 26.10) and the normal limit.
    #[test]
    fn quantiles_match_the_tables() {
        for (p, nu, t) in [
            (0.025, 6.0, 2.446_912),
            (0.005, 10.0, 3.169_273),
            (0.001, 5.0, 5.893_430),
            (0.05, 1.0, 6.313_752),
            (0.025, 1e7, 1.959_964),
        ] {
            let got = upper_quantile(p, nu);
            assert!(
                (got - t).abs() < 1e-5 * t,
                "p {p}, nu {nu}: {got} against {t}"
            );
        }
        // F's upper 5 % and 1 % points (Abramowitz & Stegun 26.9), and t^2 = F(1, nu)
        for (p, d1, d2, f) in [
            (0.05, 6.0, 10.0, 3.2172),
            (0.01, 6.0, 6.0, 8.4661),
            (0.01, 3.0, 20.0, 4.9382),
            (0.05, 1.0, 5.0, 6.6079),
        ] {
            let got = f_upper_tail(f, d1, d2);
            assert!((got - p).abs() < 1e-4 * p, "F({d1}, {d2}) at {f}: {got}");
        }
        let t = 2.446_912;
        assert!((f_upper_tail(t * t, 1.0, 6.0) - 0.05).abs() < 1e-7);
        assert_eq!(f_upper_tail(0.0, 3.0, 7.0), 1.0);
        // the tail falls as t grows, and is 1/2 at 0
        assert!((upper_tail(0.0, 4.0) - 0.5).abs() < 1e-15);
        assert!(upper_tail(2.0, 4.0) > upper_tail(3.0, 4.0));
    }

    /// Against the closed form for even degrees of freedom (`e^-x/2 sum_i<k/2 (x/2)^i / i!`)
    /// and the printed upper 5 % and 1 % points for odd ones (Abramowitz & Stegun 26.8).
    #[test]
    fn chi_square_tails_match_closed_forms_and_tables() {
        for k in [2usize, 4, 10, 50, 200, 1000] {
            for x in [
                0.1,
                1.0,
                5.0,
                k as f64,
                1.3 * k as f64,
                2.0 * k as f64 + 30.0,
            ] {
                // the terms' logarithms, summed about the largest (they overflow for large k)
                let h = 0.5 * x;
                let logs: Vec<f64> = (0..k / 2)
                    .scan(0.0f64, |l, i| {
                        if i > 0 {
                            *l += (h / i as f64).ln();
                        }
                        Some(*l)
                    })
                    .collect();
                let top = logs.iter().copied().fold(f64::MIN, f64::max);
                let sum: f64 = logs.iter().map(|l| (l - top).exp()).sum();
                let exact = (-h + top + sum.ln()).exp();
                let got = chi_square_upper_tail(x, k as f64);
                assert!(
                    (got - exact).abs() < 1e-12 + 1e-10 * exact,
                    "k {k}, x {x}: {got} against {exact}"
                );
            }
        }
        for (p, k, x) in [
            (0.05, 1.0, 3.841_459),
            (0.05, 3.0, 7.814_728),
            (0.01, 5.0, 15.086_27),
            (0.01, 29.0, 49.587_88),
        ] {
            let got = chi_square_upper_tail(x, k);
            assert!((got - p).abs() < 1e-5 * p, "k {k} at {x}: {got}");
        }
        assert_eq!(chi_square_upper_tail(0.0, 3.0), 1.0);
        assert!(chi_square_upper_tail(1e5, 10.0) < 1e-300);
    }
}
