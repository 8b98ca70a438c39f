//! Throughput of the identification methods and of the identified models' predictions:
//! `cargo bench --bench identification`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use perturbid_rs::direct::{
    design_excitation, identify_base_parameters, BaseOptions, ExcitationOptions, Weighting,
};
use perturbid_rs::local::{
    identify_local, plan_experiments, IdentifyOptions, OperatingPoint, PlanOptions,
};
use perturbid_rs::robots::a465::{self, TABLE2_Q, TABLE2_QD, TABLE2_QDD};
use perturbid_rs::Gravity;
use perturbid_rs::States;
use perturbid_rs::{rnea, simulate_plan, Data, SimulationOptions};

fn identification(c: &mut Criterion) {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    // the paper's method: crossing fits and the separated regressions of one plan
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.torque_noise = vec![0.05; n];
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let mut g = c.benchmark_group("identification");
    g.sample_size(10);
    g.bench_function("identify_local/a465/5x12", |b| {
        b.iter(|| identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap())
    });
    g.bench_function("plan_experiments/a465/5x12", |b| {
        b.iter(|| plan_experiments(&model, &op, &PlanOptions::default()).unwrap())
    });
    // base parameters from 10^5 samples (regressor, TSQR, OLS)
    let k = 100_000;
    let wave = |x: usize, f: f64| (f * ((x / n) as f64) * 1e-3 + (x % n) as f64).sin();
    let q: Vec<f64> = (0..k * n)
        .map(|x| TABLE2_Q[x % n] + 0.5 * wave(x, 1.0))
        .collect();
    let qd: Vec<f64> = (0..k * n).map(|x| wave(x, 2.0)).collect();
    let qdd: Vec<f64> = (0..k * n).map(|x| wave(x, 3.7)).collect();
    let mut data = Data::new(&model);
    let mut tau = Vec::with_capacity(k * n);
    for s in 0..k {
        let r = s * n..(s + 1) * n;
        rnea(
            &model,
            &mut data,
            &q[r.clone()],
            &qd[r.clone()],
            &qdd[r],
            Gravity::Included,
        )
        .unwrap();
        tau.extend(data.tau.iter());
    }
    let batch = States::new(model.nv, &q, Some(&qd), Some(&qdd)).unwrap();
    let ols = BaseOptions {
        weighting: Weighting::Ols,
        ..BaseOptions::default()
    };
    g.bench_function("identify_base_parameters/a465/100000", |b| {
        b.iter(|| identify_base_parameters(&model, &batch, &tau, &ols).unwrap())
    });
    // the excitation design of the paper's comparison (L = 5)
    let ex = ExcitationOptions {
        max_evaluations: 500,
        ..ExcitationOptions::default()
    };
    g.bench_function("design_excitation/a465/L5-500evals", |b| {
        b.iter(|| design_excitation(&model, &ex, None).unwrap())
    });
    g.finish();

    // predictions and their standard errors, per state, on 10,000 states of the log above:
    // the standard errors' cost as a ratio to the prediction's
    let fit = identify_base_parameters(&model, &batch, &tau, &ols).unwrap();
    let local = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let m = 10_000;
    let states = batch.slice(0..m);
    let mut g = c.benchmark_group("prediction");
    g.throughput(Throughput::Elements(m as u64));
    g.bench_function("base_model/predict", |b| {
        b.iter(|| fit.predict(&model, &states).unwrap())
    });
    g.bench_function("base_model/predict_stderr", |b| {
        b.iter(|| fit.predict_stderr(&model, &states).unwrap())
    });
    g.bench_function("local_model/predict", |b| {
        b.iter(|| local.predict(&states).unwrap())
    });
    g.bench_function("local_model/predict_stderr", |b| {
        b.iter(|| local.predict_stderr(&states).unwrap())
    });
    g.finish();
}

criterion_group!(benches, identification);
criterion_main!(benches);
