//! The paper's method end to end in Rust: plan, simulate, identify, against the analytic
//! linearisation of the dynamics core.

mod common;

use nalgebra::DMatrix;
use perturbid_rs::local::{identify_local, plan_experiments, Design, ExperimentKind, IdentifyOptions, OperatingPoint, PlanOptions};
use perturbid_rs::robots::a465;
use perturbid_rs::{linearize, simulate_plan, Data, Model, SimulationOptions};

fn table2() -> OperatingPoint {
    OperatingPoint::new(a465::TABLE2_Q.to_vec(), a465::TABLE2_QD.to_vec(), a465::TABLE2_QDD.to_vec()).unwrap()
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

fn run(model: &Model, op: &OperatingPoint, plan_opts: &PlanOptions, sim: &SimulationOptions) -> perturbid_rs::LocalModel {
    let plan = plan_experiments(model, op, plan_opts).unwrap();
    let recs = simulate_plan(model, &plan, sim).unwrap();
    let deg: usize = std::env::var("DEG").map(|v| v.parse().unwrap()).unwrap_or(2);
    let w: Option<f64> = std::env::var("WIN").ok().map(|v| v.parse().unwrap());
    let mut o = IdentifyOptions::default();
    o.fit.torque_degree = deg;
    o.fit.window = w;
    identify_local(&plan, &recs, &o).unwrap()
}

#[test]
fn a465_noise_free_table2() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let mut sim = SimulationOptions::new(&model);
    sim.gravity = false;
    for design in [Design::Random, Design::Orthogonal] {
        let opts = PlanOptions { design, ..PlanOptions::default() };
        let m = run(&model, &op, &opts, &sim);
        let mut data = Data::new(&model);
        let lin = linearize(&model, &mut data, &op.q, &op.qd, &op.qdd, false).unwrap();
        let d = &m.d.as_ref().unwrap().matrix;
        let h = &m.h.as_ref().unwrap().matrix;
        let g = &m.g.as_ref().unwrap().matrix;
        println!("{design:?} D {:e} H {:e} G {:e} T {:e}", rel(d, &lin.d), rel(h, &lin.h), rel(g, &lin.g),
            (nalgebra::DVector::from_vec(m.torque.clone()) - &lin.torque).norm());
        println!("cond D {} H {} G {}", m.d.as_ref().unwrap().cond, m.h.as_ref().unwrap().cond, m.g.as_ref().unwrap().cond);
        println!("Gs {:?}", m.g_static.as_ref().map(|e| e.matrix.norm()));
    }
}
