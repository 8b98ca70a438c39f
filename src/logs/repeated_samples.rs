//! Samples given twice to one fit: the same log twice, a copy of it under another name, or a
//! part of one log given again as a log of its own.
//!
//! A fit over several runs ([`crate::logs::stacked_states`], `identify-direct LOG LOG ...`,
//! `identify-gains`) counts every sample's noise as independent of every other's. A run given
//! twice breaks that: its noise counts twice, the standard errors shrink by `sqrt(2)` for
//! nothing, and the checks that read them see terms "beyond 3 standard errors" that are not
//! (ten copies of one A465 log made three friction terms "negative" so). Two real runs never
//! hold the same samples bit for bit, so such runs are refused, naming where they agree.
//!
//! What is compared: each sample's positions and torques (or logged signal), exactly, as a
//! 64-bit print of their bits. Runs agree where [`RUN`] or more consecutive samples of one are
//! those of another, and not all the same sample (a robot at rest logs the same quantised
//! sample again and again, in any run). Times are not compared: a copy exported with its
//! stamps shifted is still a copy. Within one run nothing is compared (a noise-free
//! simulation repeats itself every period).
//!
//! Cost: one pass over the values, and a hash map of one entry per [`STEP`] samples.

use std::collections::HashMap;

use crate::error::{Error, Result};

/// The fewest consecutive samples that two runs must share to be refused: 49 (a window of
/// `RUN - STEP + 1` samples is indexed every [`STEP`] samples, so any run of this many shared
/// samples holds one indexed window whole).
pub const RUN: usize = 2 * STEP - 1;

/// How far apart the indexed windows start (samples); a window is [`STEP`] samples long.
pub const STEP: usize = 25;

/// The prints of one run's samples: one 64-bit hash of the bits of each sample's values.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SamplePrints {
    rows: Vec<u64>,
}

impl SamplePrints {
    /// The prints of `k` samples of `n` values in each of `columns` (each row-major `k x n`:
    /// positions, torques): sample `s` reads `columns[c][s * n..(s + 1) * n]` of every column.
    /// Errors: `n` of 0, or a column whose length is no multiple of `n` or holds another
    /// number of samples than the first.
    pub fn of(n: usize, columns: &[&[f64]]) -> Result<Self> {
        let k = columns.first().map_or(0, |c| c.len() / n.max(1));
        if n == 0 || columns.iter().any(|c| c.len() != k * n) {
            return Err(Error::shape(
                "samples",
                format!("columns of k x {n} values alike"),
                format!(
                    "{:?} values",
                    columns.iter().map(|c| c.len()).collect::<Vec<_>>()
                ),
            ));
        }
        let rows = (0..k)
            .map(|s| {
                let mut h = 0x243f_6a88_85a3_08d3_u64;
                for c in columns {
                    for v in &c[s * n..(s + 1) * n] {
                        h = mix(h ^ v.to_bits());
                    }
                }
                h
            })
            .collect();
        Ok(Self { rows })
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// No samples.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// Where two runs hold the same samples: samples `at_first..at_first + len` of run `first`
/// are samples `at_second..at_second + len` of run `second` (`first < second`, indices from 0
/// in each run). `len` is the whole agreeing stretch, at least [`RUN`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SharedSamples {
    pub first: usize,
    pub second: usize,
    pub at_first: usize,
    pub at_second: usize,
    pub len: usize,
}

/// The first pair of `runs` found sharing [`RUN`] or more consecutive samples (not all one
/// sample), with the whole stretch they share; None where no two do.
pub fn find_shared_samples(runs: &[SamplePrints]) -> Option<SharedSamples> {
    const W: usize = STEP;
    // a base for the windows' polynomial hash, and its power W - 1
    const B: u64 = 0x9e37_79b9_7f4a_7c15;
    let top = (1..W).fold(1u64, |p, _| p.wrapping_mul(B));
    // the windows of every run that start at a multiple of STEP and hold two samples that
    // differ: their hash to (run, start); the first one kept where several agree
    let mut index: HashMap<u64, (usize, usize)> = HashMap::new();
    for (r, run) in runs.iter().enumerate() {
        for start in (0..run.len().saturating_sub(W - 1)).step_by(STEP) {
            let w = &run.rows[start..start + W];
            if varied(w) {
                index.entry(window_hash(w)).or_insert((r, start));
            }
        }
    }
    if index.is_empty() {
        return None;
    }
    // every window of every run against them
    for (r, run) in runs.iter().enumerate() {
        let rows = &run.rows;
        if rows.len() < W {
            continue;
        }
        let mut h = window_hash(&rows[..W]);
        // the last sample (from 1) that differs from the one before it
        let mut changed = (1..W).rev().find(|&i| rows[i] != rows[i - 1]).unwrap_or(0);
        for start in 0..=rows.len() - W {
            if start > 0 {
                let end = start + W - 1;
                h = h
                    .wrapping_sub(rows[start - 1].wrapping_mul(top))
                    .wrapping_mul(B)
                    .wrapping_add(rows[end]);
                if rows[end] != rows[end - 1] {
                    changed = end;
                }
            }
            if changed <= start {
                continue;
            }
            let Some(&(other, at)) = index.get(&h) else {
                continue;
            };
            if other == r || runs[other].rows[at..at + W] != rows[start..start + W] {
                continue;
            }
            let (a, b) = (&runs[other].rows, rows);
            // the whole stretch: back and forth from the window
            let back = (1..=at.min(start))
                .take_while(|&d| a[at - d] == b[start - d])
                .count();
            let forth = (W..)
                .take_while(|&d| at + d < a.len() && start + d < b.len())
                .take_while(|&d| a[at + d] == b[start + d])
                .count();
            let (len, at_a, at_b) = (W + back + forth, at - back, start - back);
            if len < RUN {
                continue;
            }
            let (first, second, at_first, at_second) = if other < r {
                (other, r, at_a, at_b)
            } else {
                (r, other, at_b, at_a)
            };
            return Some(SharedSamples {
                first,
                second,
                at_first,
                at_second,
                len,
            });
        }
    }
    None
}

/// Refuses `runs` (named by `names`, in messages as `run` would be: a log's path, `Recording
/// 2 ('name')`) where two share [`RUN`] or more consecutive samples ([`find_shared_samples`]),
/// as `argument`, naming the two and where they agree. `samples` says what a sample is to
/// the reader: `samples` for a run's preprocessed samples, `data rows` for a log's rows as
/// read (both counted from 1 in the message).
pub fn refuse_shared_samples(
    runs: &[SamplePrints],
    names: &[String],
    argument: &str,
    samples: &str,
) -> Result<()> {
    let Some(s) = find_shared_samples(runs) else {
        return Ok(());
    };
    let name = |r: usize| run_name(names, r);
    let span = |at: usize| format!("{} to {}", at + 1, at + s.len);
    let whole = s.len == runs[s.first].len() && s.len == runs[s.second].len();
    let what = if whole {
        format!(
            "{} and {} hold the same {} {samples}",
            name(s.first),
            name(s.second),
            s.len
        )
    } else {
        format!(
            "{samples} {} of {} (of {}) are {samples} {} of {} (of {})",
            span(s.at_second),
            name(s.second),
            runs[s.second].len(),
            span(s.at_first),
            name(s.first),
            runs[s.first].len()
        )
    };
    Err(Error::invalid(
        argument,
        format!(
            "{what}, bit for bit: the same data given twice, whose noise a fit would count as independent twice (standard errors too small by up to sqrt(2)); give each run's samples once"
        ),
    ))
}

/// A finaliser of 64-bit hashes (MurmurHash3's): every bit of `h` moves every bit of the result.
fn mix(mut h: u64) -> u64 {
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

/// The polynomial hash of a window's prints (the base of [`find_shared_samples`]).
fn window_hash(w: &[u64]) -> u64 {
    w.iter().fold(0u64, |h, &x| {
        h.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(x)
    })
}

/// A window holding two samples that differ.
fn varied(w: &[u64]) -> bool {
    w.iter().any(|&x| x != w[0])
}

/// Run `r`'s name among `names` (a log's path, a Recording's name), or `run r` (from 0) where
/// none is given.
pub fn run_name(names: &[String], r: usize) -> String {
    names.get(r).cloned().unwrap_or_else(|| format!("run {r}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run of `k` samples of 2 joints, `seed` making each run's values its own.
    fn run(k: usize, seed: f64) -> (Vec<f64>, Vec<f64>) {
        let q = (0..2 * k).map(|i| (i as f64 * 0.37 + seed).sin()).collect();
        let tau = (0..2 * k).map(|i| (i as f64 * 0.11 + seed).cos()).collect();
        (q, tau)
    }

    fn prints(q: &[f64], tau: &[f64]) -> SamplePrints {
        SamplePrints::of(2, &[q, tau]).unwrap()
    }

    #[test]
    fn different_runs_pass() {
        let (a, b) = (run(3000, 0.0), run(3000, 0.5));
        assert_eq!(
            find_shared_samples(&[prints(&a.0, &a.1), prints(&b.0, &b.1)]),
            None
        );
    }

    #[test]
    fn a_copy_is_found_whole() {
        let a = run(1000, 0.0);
        let c = run(700, 2.0);
        let runs = [prints(&c.0, &c.1), prints(&a.0, &a.1), prints(&a.0, &a.1)];
        let s = find_shared_samples(&runs).unwrap();
        assert_eq!(
            s,
            SharedSamples {
                first: 1,
                second: 2,
                at_first: 0,
                at_second: 0,
                len: 1000
            }
        );
        let e = refuse_shared_samples(
            &runs,
            &["c".into(), "a".into(), "b".into()],
            "DATA",
            "samples",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("a and b hold the same 1000 samples"), "{e}");
    }

    #[test]
    fn a_part_of_a_run_is_found_at_every_offset() {
        let a = run(600, 0.3);
        for (from, len) in [(0, 49), (1, 49), (17, 60), (24, 300), (551, 49), (300, 300)] {
            let part = (
                a.0[2 * from..2 * (from + len)].to_vec(),
                a.1[2 * from..2 * (from + len)].to_vec(),
            );
            let other = run(500, 1.0);
            // the part inside a run of its own, between other samples
            let q = [&other.0[..200], &part.0[..], &other.0[200..]].concat();
            let tau = [&other.1[..200], &part.1[..], &other.1[200..]].concat();
            let s = find_shared_samples(&[prints(&q, &tau), prints(&a.0, &a.1)])
                .unwrap_or_else(|| panic!("{from}, {len}"));
            assert_eq!(
                (s.first, s.second, s.at_first, s.at_second, s.len),
                (0, 1, 100, from, len),
                "{from}, {len}"
            );
        }
        // one sample fewer than RUN is no copy
        let q = a.0[..2 * (RUN - 1)].to_vec();
        let tau = a.1[..2 * (RUN - 1)].to_vec();
        assert_eq!(
            find_shared_samples(&[prints(&q, &tau), prints(&a.0, &a.1)]),
            None
        );
    }

    #[test]
    fn a_robot_at_rest_and_a_periodic_run_are_no_copies() {
        // two runs holding the same quantised sample again and again
        let still = vec![0.25; 2 * 500];
        let runs = [prints(&still, &still), prints(&still, &still)];
        assert_eq!(find_shared_samples(&runs), None);
        // one run that repeats itself
        let a = run(100, 0.0);
        let q = [&a.0[..], &a.0[..], &a.0[..]].concat();
        let tau = [&a.1[..], &a.1[..], &a.1[..]].concat();
        let b = run(300, 0.7);
        assert_eq!(
            find_shared_samples(&[prints(&q, &tau), prints(&b.0, &b.1)]),
            None
        );
    }

    #[test]
    fn a_torque_that_differs_in_one_bit_is_another_sample() {
        let a = run(200, 0.0);
        let mut tau = a.1.clone();
        for s in (0..200).step_by(40) {
            tau[2 * s + 1] = f64::from_bits(tau[2 * s + 1].to_bits() ^ 1);
        }
        assert_eq!(
            find_shared_samples(&[prints(&a.0, &a.1), prints(&a.0, &tau)]),
            None
        );
    }

    #[test]
    fn columns_of_other_shapes_are_refused() {
        assert!(SamplePrints::of(2, &[&[0.0; 4], &[0.0; 6]]).is_err());
        assert!(SamplePrints::of(0, &[&[]]).is_err());
        assert!(SamplePrints::of(2, &[&[0.0; 5]]).is_err());
    }
}
