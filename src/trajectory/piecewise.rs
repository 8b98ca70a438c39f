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

    /// Checks what a robot needs of a trajectory read from a file (the shapes, times and
    /// coefficients' finiteness are the caller's to check first): every segment's reference
    /// time finite and its positions, velocities and accelerations within f64's range; the
    /// segments joined without a jump in position, velocity or acceleration (C2); at rest at
    /// both ends. Each to `1e-6` relative to the magnitudes of the polynomial's terms there.
    /// The error says what broke, with the segment, joint and time.
    pub fn check_smooth(&self) -> std::result::Result<(), String> {
        const TOL: f64 = 1e-6;
        // the state at t by segment `seg`, with the size of its terms (the rounding scale)
        let at = |seg: &Segment, j: usize, t: f64| {
            let c = &seg.coeffs[j];
            let s = (t - seg.t_ref).abs();
            let mut scale = [0.0f64; 3];
            for (k, ck) in c.iter().enumerate() {
                let ck = ck.abs();
                scale[0] += ck * s.powi(k as i32);
                if k >= 1 {
                    scale[1] += k as f64 * ck * s.powi(k as i32 - 1);
                }
                if k >= 2 {
                    scale[2] += (k * (k - 1)) as f64 * ck * s.powi(k as i32 - 2);
                }
            }
            let (q, v, a) = seg.eval(j, t);
            ([q, v, a], scale)
        };
        const WHAT: [&str; 3] = ["position", "velocity", "acceleration"];
        for (i, seg) in self.segments.iter().enumerate() {
            if !seg.t_ref.is_finite() {
                return Err(format!("segments[{i}]: t_ref {} is not finite", seg.t_ref));
            }
            for j in 0..self.n {
                for t in [seg.t0, seg.t1] {
                    let (x, scale) = at(seg, j, t);
                    if let Some(d) = (0..3).find(|&d| !(x[d].is_finite() && scale[d].is_finite())) {
                        return Err(format!(
                            "segments[{i}], joint {}: the {} at t = {} s is beyond f64's range",
                            j + 1,
                            WHAT[d],
                            crate::error::shown(t)
                        ));
                    }
                }
            }
        }
        for (i, pair) in self.segments.windows(2).enumerate() {
            let t = pair[0].t1;
            for j in 0..self.n {
                let (x0, s0) = at(&pair[0], j, t);
                let (x1, s1) = at(&pair[1], j, pair[1].t0);
                for d in 0..3 {
                    if (x1[d] - x0[d]).abs() > TOL * (1.0 + s0[d].max(s1[d])) {
                        return Err(format!(
                            "joint {}: the {} jumps from {} to {} at t = {} s, between segments[{i}] and segments[{}]; a robot cannot follow a jump",
                            j + 1,
                            WHAT[d],
                            crate::error::shown(x0[d]),
                            crate::error::shown(x1[d]),
                            crate::error::shown(t),
                            i + 1
                        ));
                    }
                }
            }
        }
        let ends = [
            ("starts", self.segments.first(), self.start()),
            ("ends", self.segments.last(), self.end()),
        ];
        for (which, seg, t) in ends {
            let Some(seg) = seg else { continue };
            for j in 0..self.n {
                let (x, scale) = at(seg, j, t);
                for d in 1..3 {
                    if x[d].abs() > TOL * (1.0 + scale[d]) {
                        return Err(format!(
                            "joint {}: the trajectory {which} with {} {} at t = {} s; it must start and end at rest",
                            j + 1,
                            WHAT[d],
                            crate::error::shown(x[d]),
                            crate::error::shown(t)
                        ));
                    }
                }
            }
        }
        Ok(())
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
