//! Piecewise-polynomial joint trajectories: crossing windows (quadratics, eq. 11), dwells, and
//! quintic transitions that match position, velocity and acceleration at both ends, so the whole
//! trajectory is C2.

use serde::{Deserialize, Serialize};

use super::samples::Samples;

/// What a segment is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum SegmentKind {
    /// The quadratic window around crossing `index` of the experiment (eq. 11).
    Crossing { index: usize },
    /// The robot held at rest at static posture `index` (the G-static experiment).
    Dwell { index: usize },
    /// The robot held at rest at the operating point's posture: the reference of the
    /// G-static experiment.
    Reference,
    /// A quintic joining two segments.
    Transition,
}

/// One polynomial piece: for joint `j`, `q_j(t) = sum_k coeffs[j][k] (t - t_ref)^k`, valid on
/// `[t0, t1]` (s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    #[serde(flatten)]
    pub kind: SegmentKind,
    pub t0: f64,
    pub t1: f64,
    pub t_ref: f64,
    /// Per joint, the coefficients of `1, s, s^2, ..., s^5` with `s = t - t_ref`.
    pub coeffs: Vec<[f64; 6]>,
}

impl Segment {
    /// A segment of constant acceleration through `(q, qd, qdd)` at `t_ref` (eq. 11).
    pub fn quadratic(
        kind: SegmentKind,
        t0: f64,
        t1: f64,
        t_ref: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Self {
        let coeffs = (0..q.len())
            .map(|j| [q[j], qd[j], 0.5 * qdd[j], 0.0, 0.0, 0.0])
            .collect();
        Self {
            kind,
            t0,
            t1,
            t_ref,
            coeffs,
        }
    }

    /// Joint `j`'s position, velocity and acceleration at time `t`.
    pub fn eval(&self, j: usize, t: f64) -> (f64, f64, f64) {
        let c = &self.coeffs[j];
        let s = t - self.t_ref;
        let q = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
        let v = c[1] + s * (2.0 * c[2] + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
        let a = 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
        (q, v, a)
    }

    /// Position, velocity and acceleration of every joint at `t`.
    pub fn state(&self, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = self.coeffs.len();
        let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            (q[j], v[j], a[j]) = self.eval(j, t);
        }
        (q, v, a)
    }
}

/// The quintic coefficients (of `1, s, .., s^5`, `s` from the start) of the unique quintic that
/// goes from `(p0, v0, a0)` to `(p1, v1, a1)` in `duration` s.
pub fn quintic(p0: f64, v0: f64, a0: f64, p1: f64, v1: f64, a1: f64, duration: f64) -> [f64; 6] {
    let t = duration;
    let (t2, t3) = (t * t, t * t * t);
    let dp = p1 - p0;
    [
        p0,
        v0,
        0.5 * a0,
        (20.0 * dp - (8.0 * v1 + 12.0 * v0) * t - (3.0 * a0 - a1) * t2) / (2.0 * t3),
        (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * t + (3.0 * a0 - 2.0 * a1) * t2) / (2.0 * t3 * t),
        (12.0 * dp - 6.0 * (v1 + v0) * t - (a0 - a1) * t2) / (2.0 * t3 * t2),
    ]
}

/// A trajectory of `n` joints made of contiguous segments (`segments[i].t1 ==
/// segments[i + 1].t0`), starting at `segments[0].t0`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Trajectory {
    pub n: usize,
    pub segments: Vec<Segment>,
}

impl Trajectory {
    /// Start time (s).
    pub fn start(&self) -> f64 {
        self.segments.first().map_or(0.0, |s| s.t0)
    }

    /// End time (s).
    pub fn end(&self) -> f64 {
        self.segments.last().map_or(0.0, |s| s.t1)
    }

    /// The segment that holds time `t` (the later one at a boundary), clamped to the ends.
    pub fn segment_at(&self, t: f64) -> &Segment {
        let i = self.segments.partition_point(|s| s.t0 <= t);
        &self.segments[i.saturating_sub(1).min(self.segments.len() - 1)]
    }

    /// Samples at `rate` Hz from the start to the end (both included, when the duration is a
    /// whole number of periods): `t_i = start + i / rate`.
    pub fn sample(&self, rate: f64) -> Samples {
        let start = self.start();
        let count = ((self.end() - start) * rate + 1e-6).floor() as usize + 1;
        let mut out = Samples::with_capacity(self.n, count);
        let mut seg = 0;
        for i in 0..count {
            let t = start + i as f64 / rate;
            while seg + 1 < self.segments.len() && self.segments[seg].t1 <= t {
                seg += 1;
            }
            out.t.push(t);
            for j in 0..self.n {
                let (q, v, a) = self.segments[seg].eval(j, t);
                out.q.push(q);
                out.qd.push(v);
                out.qdd.push(a);
            }
        }
        out
    }
}
