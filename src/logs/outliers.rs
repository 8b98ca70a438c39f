//! Isolated glitches in a window of a sampled signal: single samples far off an otherwise
//! smooth signal, as a real robot's log gets them from a dropped or corrupted message, an
//! encoder's missed count or a sensor's spike (docs/method.md, section 7). Used on the local
//! method's crossing windows ([`crate::local::glitches`]) and on whole logs before
//! preprocessing ([`crate::logs::log_screening`]).
//!
//! A window's samples are screened against a least-squares fit (a basis and its weights): a
//! sample whose studentised residual, `r_i / (s sqrt(1 - h_ii))` with `h_ii` its leverage,
//! exceeds [`NOISE_LEVELS`] times the window's robust noise level `s` (1.4826 times the median
//! absolute residual, at least a floor the caller gives: the rounding of a grid, or a tiny
//! fraction of the signal's size) is a glitch. The worst one is left out, the fit repeated on
//! the rest, and so on, up to [`MAX_PER_WINDOW`]; each glitch's value is then replaced by the
//! fit of the rest, which makes the window's least-squares fit exactly the fit without them.
//! More than [`MAX_PER_WINDOW`] are not isolated (a step the fit does not model: an impact,
//! an unplanned velocity reversal) and are left in, reported as such.
//!
//! The noise level comes from the least-squares fit's own residuals, which real logs need: a
//! real torque's noise is coloured, and a level from differences of neighbouring samples read
//! it 3 to 10 times too low on the Panda log. The price is masking: a burst of more than
//! about five samples far off bends the fit towards it and raises the level, and may then go
//! unseen (docs/limits.md).

use nalgebra::DMatrix;

/// How far (in the window's robust noise levels) a sample's studentised residual must be to
/// count as a glitch. On the real Panda log of `../shared` (its 7 measured torques, 2,700
/// windows of +-0.05 s and +-0.1 s, degree 6, windows with a velocity reversal left out) the
/// largest was 6.0; Gaussian noise exceeds 10 once in 10^23 samples.
pub const NOISE_LEVELS: f64 = 10.0;

/// The most glitches left out of one signal's window; more are not isolated.
pub const MAX_PER_WINDOW: usize = 3;

/// Samples whose leverage in the fit is above this are not judged: the fit follows them too
/// closely to tell a glitch (the ends of a short window under a high degree).
const MAX_LEVERAGE: f64 = 0.95;

/// One sample found far off its window's fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flagged {
    /// Index of the sample within the window.
    pub index: usize,
    /// Its value as recorded.
    pub value: f64,
    /// Its studentised residual in robust noise levels (infinite for a value set aside at once:
    /// further than a million times the spread of its window's values from their median).
    pub noise_levels: f64,
}

/// A window's samples after screening.
#[derive(Clone, Debug, PartialEq)]
pub struct Screened {
    /// The samples, with each replaced glitch set to the fit of the others (the recorded
    /// values where nothing was replaced).
    pub values: Vec<f64>,
    /// The glitches found, worst first: replaced, or (with `isolated` false) left in.
    pub flagged: Vec<Flagged>,
    /// False when more than [`MAX_PER_WINDOW`] samples were that far off: none was replaced
    /// and `flagged` lists the first `MAX_PER_WINDOW + 1` found.
    pub isolated: bool,
}

impl Screened {
    /// The samples replaced (0 where the window was clean or not isolated).
    pub fn replaced(&self) -> usize {
        if self.isolated {
            self.flagged.len()
        } else {
            0
        }
    }
}

/// The median of `|x|` over `x` (0 for none).
fn median_abs(x: impl Iterator<Item = f64>) -> f64 {
    let mut a: Vec<f64> = x.map(f64::abs).collect();
    if a.is_empty() {
        return 0.0;
    }
    let mid = a.len() / 2;
    let (_, m, _) = a.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// A window's samples centred on their median and divided by a robust spread (at least
/// `floor`), so that no residual of ordinary samples overflows.
struct Scaled {
    centre: f64,
    spread: f64,
    values: Vec<f64>,
}

impl Scaled {
    fn new(y: &[f64], floor: f64) -> Self {
        let centre = {
            let mut s = y.to_vec();
            let mid = s.len() / 2;
            *s.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let spread = median_abs(y.iter().map(|x| x - centre)).max(floor);
        let values = y.iter().map(|x| (x - centre) / spread).collect();
        Self {
            centre,
            spread,
            values,
        }
    }
}

/// The fit of the samples `kept` (indices into the window) of `y`: their basis rows, weights
/// (the window's own while none is left out), coefficients, and each kept sample's residual
/// and leverage.
struct KeptFit<'a> {
    window: (&'a DMatrix<f64>, &'a DMatrix<f64>),
    reduced: Option<(DMatrix<f64>, DMatrix<f64>)>,
    coef: Vec<f64>,
    residual: Vec<f64>,
    leverage: Vec<f64>,
}

impl<'a> KeptFit<'a> {
    fn new(v: &'a DMatrix<f64>, w: &'a DMatrix<f64>, kept: &[usize], y: &[f64]) -> Option<Self> {
        let cols = v.ncols();
        let reduced = if kept.len() == v.nrows() {
            None
        } else {
            let vk = DMatrix::from_fn(kept.len(), cols, |r, c| v[(kept[r], c)]);
            let wk = crate::decomposition::pseudo_inverse(vk.clone(), 1e-12)?;
            Some((vk, wk))
        };
        let mut fit = Self {
            window: (v, w),
            reduced,
            coef: vec![],
            residual: vec![],
            leverage: vec![],
        };
        let (basis, weights) = fit.matrices();
        let coef: Vec<f64> = (0..cols)
            .map(|c| (0..kept.len()).map(|r| weights[(c, r)] * y[kept[r]]).sum())
            .collect();
        let row = |r: usize| -> f64 { (0..cols).map(|c| basis[(r, c)] * coef[c]).sum() };
        let residual = (0..kept.len()).map(|r| y[kept[r]] - row(r)).collect();
        let leverage = (0..kept.len())
            .map(|r| (0..cols).map(|c| basis[(r, c)] * weights[(c, r)]).sum())
            .collect();
        fit.coef = coef;
        fit.residual = residual;
        fit.leverage = leverage;
        Some(fit)
    }

    /// The kept samples' basis rows and weights.
    fn matrices(&self) -> (&DMatrix<f64>, &DMatrix<f64>) {
        match &self.reduced {
            Some((v, w)) => (v, w),
            None => self.window,
        }
    }

    /// The hat matrix's entry `(j, i)`: how much sample `i` moves the fit at sample `j`.
    fn hat(&self, j: usize, i: usize) -> f64 {
        let (basis, weights) = self.matrices();
        (0..basis.ncols())
            .map(|c| basis[(j, c)] * weights[(c, i)])
            .sum()
    }

    /// 1.4826 times the median of the studentised residuals' magnitudes, `|r_j| / sqrt(1 -
    /// h_jj)`, over the kept samples but `without` (with the fit recomputed without it).
    fn level(&self, without: Option<usize>) -> f64 {
        let shift = without.map(|i| self.residual[i] / (1.0 - self.leverage[i]));
        median_abs(
            (0..self.residual.len())
                .filter(|&j| Some(j) != without)
                .map(|j| {
                    // the residual when sample i is left out of the fit
                    let r =
                        self.residual[j] + shift.map_or(0.0, |s| self.hat(j, without.unwrap()) * s);
                    r / (1.0 - self.leverage[j]).max(1.0 - MAX_LEVERAGE).sqrt()
                }),
        ) * 1.4826
    }
}

/// The robust noise level of the samples `y` about their fit (basis `v`, weights `w`, as for
/// [`screen`]): 1.4826 times the median of their studentised residuals' magnitudes, in the
/// signal's units; 0 for a window too short to tell.
pub fn level(v: &DMatrix<f64>, w: &DMatrix<f64>, y: &[f64]) -> f64 {
    let (k, cols) = (y.len(), v.ncols());
    if k <= cols + 1 || v.nrows() != k || w.shape() != (cols, k) {
        return 0.0;
    }
    let s = Scaled::new(y, f64::MIN_POSITIVE);
    let all: Vec<usize> = (0..k).collect();
    let l = KeptFit::new(v, w, &all, &s.values).map_or(0.0, |f| f.level(None) * s.spread);
    if l.is_finite() {
        l
    } else {
        0.0
    }
}

/// A value further than this many times the spread of its window's values (their median
/// absolute deviation from their median) from their median is set aside as a glitch at once.
const GROSS: f64 = 1e6;

/// How many of the largest studentised residuals are tested, each against the level of the
/// others with it left out of the fit (a large glitch bends the fit and raises the level of
/// the rest, most in short windows).
const CANDIDATES: usize = 3;

/// Screens the samples `y` (length K) of one signal in one window for glitches, against the
/// fit with basis `v` (K x C, the basis functions at the samples) whose least-squares weights
/// are `w` (C x K, the pseudo-inverse of `v`). `floor` (the signal's units, > 0) is the
/// least noise level assumed: the signal's level over the experiment's windows, the rounding
/// error of a grid it lies on (`step / sqrt(12)`), or a tiny fraction of its size for a
/// noise-free one. Returns the samples with the glitches replaced by the fit of the others.
pub fn screen(v: &DMatrix<f64>, w: &DMatrix<f64>, y: &[f64], floor: f64) -> Screened {
    let (k, cols) = (y.len(), v.ncols());
    let unchanged = |flagged: Vec<Flagged>, isolated: bool| Screened {
        values: y.to_vec(),
        flagged,
        isolated,
    };
    if k <= cols + 1 || v.nrows() != k || w.shape() != (cols, k) {
        return unchanged(vec![], true);
    }
    let Scaled {
        centre,
        spread,
        values: mut scaled,
    } = Scaled::new(y, floor);
    let floor = floor / spread;
    let mut out: Vec<usize> = vec![];
    let mut flagged: Vec<Flagged> = vec![];
    // a value far beyond the spread of the window's values (or whose difference from them
    // overflows) is a glitch of any size, set aside before any fit: fitted with the others
    // it would leave them only rounding errors of its own size
    for i in 0..k {
        let gross = !scaled[i].is_finite() || scaled[i].abs() > GROSS;
        if gross || !(y[i] - centre).is_finite() {
            scaled[i] = 0.0;
            out.push(i);
            flagged.push(Flagged {
                index: i,
                value: y[i],
                noise_levels: f64::INFINITY,
            });
        }
    }
    loop {
        if out.len() > MAX_PER_WINDOW {
            flagged.truncate(MAX_PER_WINDOW + 1);
            return unchanged(flagged, false);
        }
        let kept: Vec<usize> = (0..k).filter(|i| !out.contains(i)).collect();
        if kept.len() <= cols + 1 {
            return unchanged(flagged, false);
        }
        let Some(fit) = KeptFit::new(v, w, &kept, &scaled) else {
            return unchanged(flagged, false);
        };
        let studentised = |r: usize| fit.residual[r].abs() / (1.0 - fit.leverage[r]).sqrt();
        let mut candidates: Vec<usize> = (0..kept.len())
            .filter(|&r| fit.leverage[r] < MAX_LEVERAGE)
            .collect();
        candidates.sort_by(|&a, &b| studentised(b).total_cmp(&studentised(a)));
        candidates.truncate(CANDIDATES);
        let worst = candidates
            .into_iter()
            .map(|r| (r, studentised(r) / fit.level(Some(r)).max(floor)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((r, z)) if z > NOISE_LEVELS => {
                out.push(kept[r]);
                flagged.push(Flagged {
                    index: kept[r],
                    value: y[kept[r]],
                    noise_levels: z,
                });
            }
            _ => {
                if flagged.is_empty() {
                    return unchanged(vec![], true);
                }
                let mut values = y.to_vec();
                for &i in &out {
                    let at: f64 = (0..cols).map(|c| v[(i, c)] * fit.coef[c]).sum();
                    values[i] = centre + spread * at;
                }
                return Screened {
                    values,
                    flagged,
                    isolated: true,
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The basis and weights of a polynomial fit of degree `degree` at `k` samples on [-1, 1].
    fn polynomial(k: usize, degree: usize) -> (DMatrix<f64>, DMatrix<f64>) {
        let v = DMatrix::from_fn(k, degree + 1, |i, d| {
            (-1.0 + 2.0 * i as f64 / (k - 1) as f64).powi(d as i32)
        });
        let w = v.clone().pseudo_inverse(1e-12).unwrap();
        (v, w)
    }

    /// Gaussian-like noise (the sum of 12 uniforms minus 6), deterministic.
    fn noise(k: usize, seed: u64) -> Vec<f64> {
        let mut s = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..k)
            .map(|_| {
                (0..12)
                    .map(|_| {
                        s = s
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        (s >> 11) as f64 / (1u64 << 53) as f64
                    })
                    .sum::<f64>()
                    - 6.0
            })
            .collect()
    }

    fn signal(k: usize, seed: u64, sigma: f64) -> Vec<f64> {
        let e = noise(k, seed);
        (0..k)
            .map(|i| {
                let u = -1.0 + 2.0 * i as f64 / (k - 1) as f64;
                3.0 + 0.7 * u - 0.4 * u * u + 0.05 * u.powi(5) + sigma * e[i]
            })
            .collect()
    }

    #[test]
    fn clean_noisy_windows_are_left_alone() {
        let (v, w) = polynomial(101, 6);
        for seed in 0..200 {
            let y = signal(101, seed, 0.05);
            let s = screen(&v, &w, &y, 1e-8);
            assert!(s.flagged.is_empty(), "seed {seed}: {:?}", s.flagged);
            assert_eq!(s.values, y);
        }
    }

    #[test]
    fn noise_free_windows_are_left_alone() {
        let (v, w) = polynomial(101, 6);
        let y = signal(101, 0, 0.0);
        let floor = 1e-8 * y.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(screen(&v, &w, &y, floor).flagged.is_empty());
        // a constant signal (a flat channel) with a floor of its grid's rounding
        let flat = vec![0.25; 101];
        assert!(screen(&v, &w, &flat, 0.01 / 12f64.sqrt())
            .flagged
            .is_empty());
        // one reading a step of its grid off is rounding, not a glitch
        let mut toggled = flat.clone();
        toggled[40] = 0.26;
        assert!(screen(&v, &w, &toggled, 0.01 / 12f64.sqrt())
            .flagged
            .is_empty());
    }

    /// A glitch replaced by the fit of the others makes the window's fit exactly the fit
    /// without it: checked against the fit of the samples left after removing it.
    #[test]
    fn glitches_are_replaced_by_the_fit_without_them() {
        let (v, w) = polynomial(101, 6);
        let clean = signal(101, 7, 0.05);
        let mut y = clean.clone();
        y[30] += 50.0;
        y[77] -= 3.0;
        y[0] = 1e300; // at an end, and far beyond any scale
        let s = screen(&v, &w, &y, 1e-8);
        assert!(s.isolated);
        let mut found: Vec<usize> = s.flagged.iter().map(|f| f.index).collect();
        found.sort();
        assert_eq!(found, vec![0, 30, 77]);
        assert_eq!(s.replaced(), 3);
        assert_eq!(s.flagged[0].value, 1e300);
        let kept: Vec<usize> = (0..101).filter(|i| ![0, 30, 77].contains(i)).collect();
        let vk = DMatrix::from_fn(kept.len(), 7, |r, c| v[(kept[r], c)]);
        let wk = vk.pseudo_inverse(1e-12).unwrap();
        let without: Vec<f64> = (0..7)
            .map(|c| (0..kept.len()).map(|r| wk[(c, r)] * y[kept[r]]).sum())
            .collect();
        let with: Vec<f64> = (0..7)
            .map(|c| (0..101).map(|i| w[(c, i)] * s.values[i]).sum())
            .collect();
        for c in 0..7 {
            assert!(
                (with[c] - without[c]).abs() < 1e-9,
                "{c}: {with:?} {without:?}"
            );
        }
        // the recorded values elsewhere are untouched
        for i in kept {
            assert_eq!(s.values[i], y[i]);
        }
    }

    #[test]
    fn many_outliers_are_not_isolated_glitches() {
        let (v, w) = polynomial(101, 6);
        let mut y = signal(101, 3, 0.05);
        // four samples held 100 noise levels off: a burst, not isolated glitches
        for x in &mut y[60..64] {
            *x += 5.0;
        }
        let s = screen(&v, &w, &y, 1e-8);
        assert!(!s.isolated, "{:?}", s.flagged);
        assert_eq!(s.flagged.len(), MAX_PER_WINDOW + 1);
        assert_eq!(s.replaced(), 0);
        assert_eq!(s.values, y);
    }

    #[test]
    fn short_or_mismatched_windows_are_not_judged() {
        let (v, w) = polynomial(8, 6);
        let y = vec![0.0, 0.0, 0.0, 9.0, 0.0, 0.0, 0.0, 0.0];
        assert!(screen(&v, &w, &y, 1e-8).flagged.is_empty());
        let (v, w) = polynomial(20, 2);
        assert!(screen(&v, &w, &[1.0; 19], 1e-8).flagged.is_empty());
    }
}
