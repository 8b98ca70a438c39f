//! The checks a plan read from a file must pass beyond its shapes and its trajectory's
//! smoothness ([`super::plan`]'s `Plan::validate`): its parts agree with each other, so that
//! no hand edit of one part is fitted by one part and diagnosed by another.

use super::plan::{Crossing, Experiment, ExperimentKind, Plan};
use crate::error::shown;
use crate::trajectory::SegmentKind;

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
