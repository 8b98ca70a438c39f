//! A local model in a few lines of text: its clock offsets, the velocity reversals it handled,
//! T* and each matrix with their standard errors and conditioning, and the torque noise it
//! measured. What `perturbid identify` prints.

use std::fmt::Write;

use nalgebra::DMatrix;

use super::diagnostics::{ReversalHandling, TorqueNoise};
use super::model::LocalModel;

impl LocalModel {
    /// The model's summary; `saved_as` names the file the model is written to, where its
    /// diagnostics can be read in full.
    pub fn summary(&self, saved_as: &str) -> String {
        let mut out = String::new();
        let offsets: Vec<String> = (self.diagnostics.offsets.iter())
            .map(|o| format!("{} {:+.2} ms", o.experiment, 1e3 * o.offset))
            .collect();
        let _ = writeln!(out, "clock offsets: {}", offsets.join(", "));
        let reversals = &self.diagnostics.reversals;
        if !reversals.is_empty() {
            let stepped = (reversals.iter())
                .filter(|r| r.handling == ReversalHandling::Step)
                .count();
            let _ = writeln!(
                out,
                "velocity reversals near crossings: {} torque fit(s) narrowed to leave the friction step out, {stepped} with the step modelled; see \"diagnostics\" in {saved_as}",
                reversals.len() - stepped,
            );
        }
        let t: Vec<String> = (self.torque.iter().zip(&self.torque_stderr))
            .map(|(t, s)| format!("{t:.4} [{s:.1e}]"))
            .collect();
        let _ = writeln!(out, "T* (N m): {}", t.join(", "));
        if let Some(d) = &self.diagnostics.torque_delay {
            let _ = writeln!(out, "{}", d.line());
        }
        if let Some(m) = &self.miss {
            let units = |v: &[f64]| -> String {
                let cells: Vec<String> = v.iter().map(|x| format!("{x:+.2}")).collect();
                cells.join(", ")
            };
            let _ = writeln!(
                out,
                "the nominal passes missed the operating point by (in perturbations, per joint): q {}; qd {}; qdd {}",
                units(&m.q_perturbations),
                units(&m.qd_perturbations),
                units(&m.qdd_perturbations)
            );
            if let Some((j, var, z)) = m.largest_in_stderr() {
                let _ = writeln!(
                    out,
                    "the largest miss is {:.1} standard errors of its measurement ({var} of joint '{}'){}",
                    z.abs(),
                    self.joint_names[j],
                    if z.abs() < 3.0 {
                        ": within what the readings may be off by, which refining the plan does not remove"
                    } else {
                        ""
                    }
                );
            }
            let c: Vec<String> = (m.correction.iter().zip(&m.correction_stderr))
                .map(|(c, s)| format!("{c:+.4} [{s:.1e}]"))
                .collect();
            let _ = writeln!(
                out,
                "T* carried to the planned point by (N m): {}",
                c.join(", ")
            );
        }
        for (name, e) in [
            ("D*", &self.d),
            ("H*", &self.h),
            ("G*", &self.g),
            ("Gs", &self.g_static),
        ] {
            if let Some(e) = e {
                let _ = writeln!(
                    out,
                    "{name}: cond(X) {:.3}, {} crossings, residual RMS max {:.2e} N m",
                    e.cond,
                    e.crossings,
                    e.residual_rms.iter().cloned().fold(0.0, f64::max)
                );
                matrix_lines(&mut out, name, &e.matrix, &e.stderr);
            }
        }
        noise_lines(&mut out, &self.diagnostics.noise, &self.joint_names);
        out
    }
}

/// The matrix `m` with its standard errors `se`, a row a line.
fn matrix_lines(out: &mut String, name: &str, m: &DMatrix<f64>, se: &DMatrix<f64>) {
    let _ = writeln!(out, "{name} (standard errors in brackets):");
    for i in 0..m.nrows() {
        let cells: Vec<String> = (0..m.ncols())
            .map(|j| format!("{:>9.4} [{:.1e}]", m[(i, j)], se[(i, j)]))
            .collect();
        let _ = writeln!(out, "  {}", cells.join(" "));
    }
}

/// The torque noise per experiment and joint: one sample's, and what varied from pass to
/// pass beyond it (`-` where not estimated).
fn noise_lines(out: &mut String, noise: &[TorqueNoise], joints: &[String]) {
    if noise.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "torque noise (N m; one sample's / what varied from pass to pass beyond it; the steps of a torque logged coarser than its noise; the encoder steps of positions read by their band):"
    );
    let mut experiments: Vec<&str> = noise.iter().map(|e| e.experiment.as_str()).collect();
    experiments.dedup();
    for x in experiments {
        let cells: Vec<String> = joints
            .iter()
            .map(|j| {
                noise
                    .iter()
                    .find(|e| e.experiment == x && &e.joint == j)
                    .map_or("-".into(), |e| {
                        let passes = e.passes.map_or("-".into(), |p| format!("{p:.1e}"));
                        let step = e
                            .step
                            .map_or(String::new(), |q| format!(" (steps {q:.1e})"));
                        let encoder = e
                            .position_step
                            .map_or(String::new(), |q| format!(" (encoder {q:.1e} rad)"));
                        format!("{:.1e} / {passes}{step}{encoder}", e.samples)
                    })
            })
            .collect();
        let _ = writeln!(out, "  {x:<9} {}", cells.join(", "));
    }
}
