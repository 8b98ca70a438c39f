//! Floating-point operations per sample of every multi-sample kernel, on the robots of the
//! speed comparison, counted by the lanes themselves (see `perturbid_rs::simd::flops`):
//!
//!     cargo run --release --features count-flops --example flop_count
//!
//! Prints one JSON object per line: `robot`, `kernel`, `flops_per_sample`. benches/README.md
//! divides these by the measured time per sample for the achieved rate.

#[path = "../tests/common/mod.rs"]
mod common;

use perturbid_rs::algorithms::batch::{
    derivatives_batch, linearize_batch, DerivativesOut, LinearizationsOut,
};
use perturbid_rs::simd::flops;
use perturbid_rs::{mass_matrix_batch, regressor_batch, rnea_batch, Gravity, Isa, LaneData};

fn main() -> perturbid_rs::Result<()> {
    let isa = Isa::detect();
    if isa == Isa::Scalar {
        eprintln!("no vector instruction set here: the scalar path counts nothing");
        std::process::exit(1);
    }
    let k = 64 * isa.lanes(); // whole groups: no padded lanes
    for (robot, model) in common::speed_robots() {
        let (n, p) = (model.nv, 10 * model.nbodies());
        let mut rng = common::Rng(3);
        let (q, qd, qdd) = (
            rng.vector(k * n, 3.0),
            rng.vector(k * n, 2.0),
            rng.vector(k * n, 2.0),
        );
        let mut lanes = LaneData::with_isa(&model, isa)?;
        let mut tau = vec![0.0; k * n];
        let mut mats = vec![vec![0.0; k * n * n]; 5];
        let mut y = vec![0.0; k * n * p];
        let g = Gravity::Included;
        let report = |kernel: &str| {
            let per = flops::take() as f64 / k as f64;
            println!("{{\"robot\": \"{robot}\", \"kernel\": \"{kernel}\", \"flops_per_sample\": {per:.1}}}");
        };
        flops::take();
        rnea_batch(&model, &mut lanes, &q, Some(&qd), Some(&qdd), g, &mut tau)?;
        report("rnea");
        mass_matrix_batch(&model, &mut lanes, &q, &mut mats[0])?;
        report("mass_matrix");
        regressor_batch(&model, &mut lanes, &q, &qd, &qdd, g, &mut y)?;
        report("regressor");
        let [dq, dv, m, d, h] = &mut mats[..] else {
            unreachable!()
        };
        let out = DerivativesOut {
            tau: &mut tau,
            dtau_dq: dq,
            dtau_dv: dv,
            m,
        };
        derivatives_batch(&model, &mut lanes, &q, &qd, &qdd, g, out)?;
        report("rnea_derivatives");
        let out = LinearizationsOut {
            torque: &mut tau,
            d,
            h,
            g: dq,
            g_static: dv,
        };
        linearize_batch(&model, &mut lanes, &q, &qd, &qdd, g, out)?;
        report("linearize");
    }
    Ok(())
}
