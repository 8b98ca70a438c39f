//! An experiment's trajectory assembled on the sampling grid: rest, transitions (quintics
//! within the transition limits), dwells at rest and the quadratic crossing windows of a plan
//! (docs/method.md, section 5). Times are sample counts over the rate, so every window starts
//! and ends on a sample.

use super::plan::Crossing;
use crate::trajectory::{transition, Segment, SegmentKind, Trajectory, TransitionLimits};

/// Builds one experiment's trajectory on the sampling grid (times are sample counts / rate).
pub(super) struct TrajectoryBuilder<'a> {
    n: usize,
    rate: f64,
    lim: &'a TransitionLimits,
    min_transition: f64,
    /// Current end of the trajectory (samples) and the state there (`[q, qd, qdd]` per joint).
    now: usize,
    state: Option<Vec<[f64; 3]>>,
    segments: Vec<Segment>,
}

impl<'a> TrajectoryBuilder<'a> {
    /// Starts at rest at `start`.
    pub(super) fn new(
        n: usize,
        rate: f64,
        lim: &'a TransitionLimits,
        min_transition: f64,
        start: &[f64],
    ) -> Self {
        let state = Some(start.iter().map(|&q| [q, 0.0, 0.0]).collect());
        Self {
            n,
            rate,
            lim,
            min_transition,
            now: 0,
            state,
            segments: Vec::new(),
        }
    }

    fn time(&self, samples: usize) -> f64 {
        samples as f64 / self.rate
    }

    /// Appends a transition from the current state to `to` (none if already there).
    pub(super) fn go_to(&mut self, to: Vec<[f64; 3]>) {
        let from = self.state.take().expect("the builder always has a state");
        if from == to {
            self.state = Some(to);
            return;
        }
        let samples = transition(&from, &to, self.lim, self.rate, self.min_transition, 30.0);
        let duration = samples as f64 / self.rate;
        let coeffs = (0..self.n)
            .map(|j| {
                crate::trajectory::quintic(
                    from[j][0], from[j][1], from[j][2], to[j][0], to[j][1], to[j][2], duration,
                )
            })
            .collect();
        let t0 = self.time(self.now);
        self.now += samples;
        self.segments.push(Segment {
            kind: SegmentKind::Transition,
            t0,
            t1: self.time(self.now),
            t_ref: t0,
            coeffs,
        });
        self.state = Some(to);
    }

    /// Holds the rest posture `c.q` for `samples`; returns `c` with its time set to the middle.
    pub(super) fn dwell(&mut self, kind: SegmentKind, mut c: Crossing, samples: usize) -> Crossing {
        self.go_to(c.q.iter().map(|&q| [q, 0.0, 0.0]).collect());
        let (t0, t1) = (self.time(self.now), self.time(self.now + samples));
        c.time = self.time(self.now + samples / 2);
        let zero = vec![0.0; self.n];
        self.segments
            .push(Segment::quadratic(kind, t0, t1, c.time, &c.q, &zero, &zero));
        self.now += samples;
        c
    }

    /// The crossing window of `c` (quadratic for `+-half` samples); returns `c` with its time.
    pub(super) fn crossing(&mut self, index: usize, mut c: Crossing, half: usize) -> Crossing {
        let h = self.time(half);
        let start = (0..self.n)
            .map(|j| {
                [
                    c.q[j] - c.qd[j] * h + 0.5 * c.qdd[j] * h * h,
                    c.qd[j] - c.qdd[j] * h,
                    c.qdd[j],
                ]
            })
            .collect();
        self.go_to(start);
        let t0 = self.time(self.now);
        c.time = self.time(self.now + half);
        let t1 = self.time(self.now + 2 * half);
        self.segments.push(Segment::quadratic(
            SegmentKind::Crossing { index },
            t0,
            t1,
            c.time,
            &c.q,
            &c.qd,
            &c.qdd,
        ));
        self.now += 2 * half;
        self.state = Some(
            (0..self.n)
                .map(|j| {
                    [
                        c.q[j] + c.qd[j] * h + 0.5 * c.qdd[j] * h * h,
                        c.qd[j] + c.qdd[j] * h,
                        c.qdd[j],
                    ]
                })
                .collect(),
        );
        c
    }

    /// Ends at rest at `q`.
    pub(super) fn finish(mut self, q: &[f64]) -> Trajectory {
        self.go_to(q.iter().map(|&q| [q, 0.0, 0.0]).collect());
        Trajectory {
            n: self.n,
            segments: self.segments,
        }
    }
}
