//! A plan as a JSON document, and the checks a plan read from a file must pass: its shapes and
//! its trajectories' smoothness, and beyond them that its parts agree with each other, so that
//! no hand edit of one part is fitted by one part and diagnosed by another.

use super::plan::{Crossing, Experiment, ExperimentKind, Plan};
use crate::document::{invalid, Document};
use crate::error::shown;
use crate::error::Result;
use crate::trajectory::SegmentKind;

impl Document for Plan {
    const FORMAT: &'static str = "perturbid-plan";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "plan";

    /// Checks that every experiment is for the plan's joints and the rate is positive; that each
    /// trajectory is finite, smooth and passes its crossings; that the crossings are the
    /// operating point moved by the perturbations (`plan_checks`); and that no
    /// experiment is planned twice.
    fn validate(&self) -> Result<()> {
        let plan = self;
        let n = plan.n();
        let bad = |m: String| invalid(Self::WHAT, m);
        if plan.joint_names.len() != n || plan.op.qd.len() != n || plan.op.qdd.len() != n {
            return Err(bad(format!(
                "the operating point and joint names disagree on the number of joints ({n})"
            )));
        }
        for e in &plan.experiments {
            if e.trajectory.n != n || e.deltas.ncols() != n || e.trajectory.segments.is_empty() {
                return Err(bad(format!(
                    "experiment '{}' is not for {n} joints",
                    e.kind.name()
                )));
            }
            if e.trajectory.segments.iter().any(|s| s.coeffs.len() != n) {
                return Err(bad(format!(
                    "experiment '{}' has a segment that is not for {n} joints",
                    e.kind.name()
                )));
            }
        }
        if !(plan.rate.is_finite() && plan.rate > 0.0 && plan.rate <= crate::limits::MAX_RATE) {
            return Err(bad(format!(
                "rate {} Hz; expected a positive number up to {:e}",
                plan.rate,
                crate::limits::MAX_RATE
            )));
        }
        if plan.experiments.is_empty() {
            return Err(bad("the plan has no experiment".into()));
        }
        crate::document::check_joint_names(Self::WHAT, &plan.joint_names)?;
        for (k, e) in plan.experiments.iter().enumerate() {
            let at = |what: &str| format!("experiments[{k}] ('{}'): {what}", e.kind.name());
            // segments in time order, end to end, finite: what sampling walks through
            let mut previous: Option<f64> = None;
            for (i, seg) in e.trajectory.segments.iter().enumerate() {
                let ordered = seg.t0.is_finite() && seg.t1.is_finite() && seg.t0 <= seg.t1;
                let joined = previous.is_none_or(|t| (seg.t0 - t).abs() <= 1e-9 * t.abs().max(1.0));
                if !ordered || !joined {
                    return Err(bad(at(&format!(
                        "trajectory.segments[{i}] runs from {} to {} s; segments must be finite, in time order and end to end",
                        seg.t0, seg.t1
                    ))));
                }
                if seg.coeffs.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(bad(at(&format!(
                        "trajectory.segments[{i}] has a coefficient that is not finite"
                    ))));
                }
                previous = Some(seg.t1);
            }
            // t, q, qd, qdd and the torques a recording of it adds
            crate::limits::sample_count(&at("trajectory"), e.duration(), plan.rate, 1 + 4 * n)?;
            e.trajectory
                .check_smooth()
                .map_err(|m| bad(at(&format!("trajectory: {m}"))))?;
            if e.deltas.nrows() != e.crossings.len() && e.kind != ExperimentKind::Nominal {
                return Err(bad(at(&format!(
                    "{} perturbations for {} crossings",
                    e.deltas.nrows(),
                    e.crossings.len()
                ))));
            }
            let (start, end) = (e.trajectory.start(), e.trajectory.end());
            if let Some(k) =
                (1..e.crossings.len()).find(|&k| e.crossings[k].time < e.crossings[k - 1].time)
            {
                return Err(bad(at(&format!(
                    "crossings[{k}] at t = {} s comes before crossings[{}] at {} s; crossings are in time order",
                    shown(e.crossings[k].time),
                    k - 1,
                    shown(e.crossings[k - 1].time)
                ))));
            }
            check_commanded(e, n).map_err(|m| bad(at(&m)))?;
            // every crossing (and the reference posture), with its refinement's offset, is a
            // state the trajectory passes
            let named = e
                .crossings
                .iter()
                .enumerate()
                .map(|(k, c)| (format!("crossings[{k}]"), c, Some(k)))
                .chain(
                    e.reference
                        .iter()
                        .map(|c| ("reference".to_string(), c, None)),
                );
            for (name, c, index) in named {
                if [&c.q, &c.qd, &c.qdd].iter().any(|v| v.len() != n) {
                    return Err(bad(at(&format!("{name} is not for {n} joints"))));
                }
                if !(c.time >= start && c.time <= end) {
                    return Err(bad(at(&format!(
                        "{name} at t = {} s is outside the trajectory ({} to {} s)",
                        shown(c.time),
                        shown(start),
                        shown(end)
                    ))));
                }
                let [cq, cqd, cqdd] = e
                    .commanded_state(index)
                    .expect("a crossing of the experiment");
                let (q, qd, qdd) = e.trajectory.segment_at(c.time).state(c.time);
                for (what, planned, passed) in
                    [("q", &cq, &q), ("qd", &cqd, &qd), ("qdd", &cqdd, &qdd)]
                {
                    if let Some(j) = (0..n).find(|&j| {
                        let off = (planned[j] - passed[j]).abs();
                        off.is_nan() || off > 1e-6 * (1.0 + planned[j].abs())
                    }) {
                        return Err(bad(at(&format!(
                            "{name}.{what}[{j}] is {} (commanded), but the trajectory passes {} at t = {} s: the crossing and the trajectory disagree",
                            shown(planned[j]),
                            shown(passed[j]),
                            shown(c.time)
                        ))));
                    }
                }
            }
            if !(e.window.is_finite() && e.window > 0.0) {
                return Err(bad(at(&format!("window {} s is not positive", e.window))));
            }
            check_planned_states(plan, e).map_err(|m| bad(at(&m)))?;
            check_windows(e).map_err(|m| bad(at(&m)))?;
            if let Some(first) = plan.experiments[..k].iter().position(|o| o.kind == e.kind) {
                return Err(bad(format!(
                    "experiments[{first}] and experiments[{k}] are both '{}'; a plan holds each experiment once",
                    e.kind.name()
                )));
            }
        }
        Ok(())
    }
}

/// Checks that an experiment's crossings (and G-static's reference) are the states its kind and
/// perturbations say: the operating point with the perturbed variable moved by the row of
/// `deltas` (G-static: at rest at `q* + dq`, its reference at rest at `q*`), and that a nominal
/// experiment's perturbations are zero. To `1e-6` relative, as the crossings against the
/// trajectory. The message names the crossing, variable and joint (a hand-edited plan whose
/// parts disagree would otherwise be fitted by one part and diagnosed by another).
pub(super) fn check_planned_states(plan: &Plan, e: &Experiment) -> std::result::Result<(), String> {
    let n = plan.n();
    let op = &plan.op;
    if e.kind == ExperimentKind::Nominal {
        if let Some((k, j)) = (0..e.deltas.nrows())
            .flat_map(|k| (0..n).map(move |j| (k, j)))
            .find(|&(k, j)| e.deltas[(k, j)] != 0.0)
        {
            return Err(format!(
                "deltas[{k}][{j}] is {}; the nominal experiment perturbs nothing",
                shown(e.deltas[(k, j)])
            ));
        }
    }
    let is_static = e.kind == ExperimentKind::GStatic;
    match (is_static, e.reference.is_some()) {
        (true, false) => {
            return Err("it has no reference; G_static's static torques are measured against a rest posture at q*".into())
        }
        (false, true) => {
            return Err(format!(
                "it has a reference; only G_static measures against a rest posture (the {} experiment's changes are measured against the nominal one)",
                e.kind.name()
            ))
        }
        _ => {}
    }
    let rest = vec![0.0; n];
    let (qd, qdd) = if is_static {
        (&rest, &rest)
    } else {
        (&op.qd, &op.qdd)
    };
    const NAMES: [&str; 3] = ["q", "qd", "qdd"];
    let compare = |name: &str, c: &Crossing, delta: Option<usize>| {
        for (v, (planned, held)) in [(&c.q, &op.q), (&c.qd, qd), (&c.qdd, qdd)]
            .into_iter()
            .enumerate()
        {
            let moved = delta.filter(|_| e.kind.perturbed() == Some(v));
            for j in 0..n {
                let expected = held[j] + moved.map_or(0.0, |k| e.deltas[(k, j)]);
                let off = (planned[j] - expected).abs();
                if off.is_nan() || off > 1e-6 * (1.0 + expected.abs()) {
                    let source = match (moved, is_static && v > 0) {
                        (Some(k), _) => {
                            format!("the operating point's {}* plus deltas[{k}] give", NAMES[v])
                        }
                        (None, true) => "a static posture has".to_string(),
                        (None, false) => format!("the operating point's {}* is", NAMES[v]),
                    };
                    return Err(format!(
                        "{name}.{}[{j}] is {}, but {source} {}: the crossing, the operating point and the perturbations disagree",
                        NAMES[v],
                        shown(planned[j]),
                        shown(expected)
                    ));
                }
            }
        }
        Ok(())
    };
    for (k, c) in e.crossings.iter().enumerate() {
        let delta = (k < e.deltas.nrows()).then_some(k);
        compare(&format!("crossings[{k}]"), c, delta)?;
    }
    if let Some(reference) = &e.reference {
        compare("reference", reference, None)?;
    }
    Ok(())
}

/// Checks that every crossing (and G-static's reference) has its one segment of the
/// trajectory, of the kind the experiment plans (a crossing window, or a dwell in G-static),
/// centred on its time, and that the fit window `+-window` lies inside it: the identification
/// fits each crossing's recording there as the segment's polynomial, so a window reaching into
/// a transition would be fitted with the wrong model (and blamed on the robot's tracking).
pub(super) fn check_windows(e: &Experiment) -> std::result::Result<(), String> {
    let is_static = e.kind == ExperimentKind::GStatic;
    let kind_of = |k: usize| {
        if is_static {
            SegmentKind::Dwell { index: k }
        } else {
            SegmentKind::Crossing { index: k }
        }
    };
    let segments = &e.trajectory.segments;
    if let Some((i, seg)) = segments.iter().enumerate().find(|(_, seg)| match seg.kind {
        SegmentKind::Crossing { index } => is_static || index >= e.crossings.len(),
        SegmentKind::Dwell { index } => !is_static || index >= e.crossings.len(),
        SegmentKind::Reference => !is_static,
        SegmentKind::Transition => false,
    }) {
        return Err(format!(
            "trajectory.segments[{i}] is {}, which the {} experiment with {} crossings does not have",
            segment_label(seg.kind),
            e.kind.name(),
            e.crossings.len()
        ));
    }
    let named = e
        .crossings
        .iter()
        .enumerate()
        .map(|(k, c)| (format!("crossings[{k}]"), kind_of(k), c))
        .chain(
            e.reference
                .iter()
                .map(|c| ("reference".to_string(), SegmentKind::Reference, c)),
        );
    for (name, kind, c) in named {
        let mut own = segments.iter().enumerate().filter(|(_, s)| s.kind == kind);
        let (Some((i, seg)), None) = (own.next(), own.next()) else {
            return Err(format!(
                "{name} needs exactly one trajectory segment, {}",
                segment_label(kind)
            ));
        };
        let tol = 1e-9 * c.time.abs().max(1.0);
        let centred = (seg.t_ref - c.time).abs() <= tol;
        let inside = c.time - e.window >= seg.t0 - tol && c.time + e.window <= seg.t1 + tol;
        if !(centred && inside) {
            return Err(format!(
                "{name} at t = {} s with window +-{} s is not inside its segment, trajectory.segments[{i}] ({} to {} s, centred on {} s): the fit would reach beyond the crossing's planned motion",
                shown(c.time),
                shown(e.window),
                shown(seg.t0),
                shown(seg.t1),
                shown(seg.t_ref)
            ));
        }
    }
    Ok(())
}

/// A segment's kind as a plan file writes it (for messages).
fn segment_label(kind: SegmentKind) -> String {
    match kind {
        SegmentKind::Crossing { index } => format!("a 'crossing' segment with index {index}"),
        SegmentKind::Dwell { index } => format!("a 'dwell' segment with index {index}"),
        SegmentKind::Reference => "a 'reference' segment".into(),
        SegmentKind::Transition => "a 'transition' segment".into(),
    }
}

/// Checks a refined experiment's offsets: one per crossing (and one for a reference posture,
/// none without), each of `n` finite values per variable, within what a robot's tracking
/// misses by (docs/limits.md).
fn check_commanded(e: &Experiment, n: usize) -> std::result::Result<(), String> {
    let Some(c) = &e.commanded else {
        return Ok(());
    };
    if c.crossings.len() != e.crossings.len() {
        return Err(format!(
            "commanded.crossings has {} offsets for {} crossings",
            c.crossings.len(),
            e.crossings.len()
        ));
    }
    if c.reference.is_some() != e.reference.is_some() {
        return Err("commanded.reference is given where the experiment has no reference posture, or missing where it has one".into());
    }
    let named = (c.crossings.iter().enumerate())
        .map(|(k, o)| (format!("commanded.crossings[{k}]"), o))
        .chain(
            c.reference
                .iter()
                .map(|o| ("commanded.reference".to_string(), o)),
        );
    for (name, o) in named {
        for (what, v, max) in [
            ("q", &o.q, 1.0),
            ("qd", &o.qd, 10.0),
            ("qdd", &o.qdd, 100.0),
        ] {
            if v.len() != n {
                return Err(format!(
                    "{name}.{what} has {} entries for {n} joints",
                    v.len()
                ));
            }
            if let Some(j) = v.iter().position(|x| !(x.is_finite() && x.abs() <= max)) {
                return Err(format!(
                    "{name}.{what}[{j}] is {}; expected an offset within +-{max} (a tracking error)",
                    v[j]
                ));
            }
        }
    }
    Ok(())
}
