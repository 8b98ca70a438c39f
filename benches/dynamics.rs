//! Throughput of the dynamics core on the built-in A465: `cargo bench --bench dynamics`.

use criterion::{criterion_group, criterion_main, Criterion};
use perturbid_rs::robots::a465::{TABLE2_Q, TABLE2_QD, TABLE2_QDD};
use perturbid_rs::{
    forward_dynamics, gravity_torque, linearize, mass_matrix, rnea, rnea_derivatives, robots, Data,
};
use std::hint::black_box;

fn dynamics(c: &mut Criterion) {
    let model = robots::builtin("a465").expect("built-in A465");
    let mut data = Data::new(&model);
    let (q, qd, qdd) = (TABLE2_Q, TABLE2_QD, TABLE2_QDD);
    c.bench_function("rnea/a465/1", |b| {
        b.iter(|| {
            rnea(
                &model,
                &mut data,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                true,
            )
            .unwrap()
        })
    });
    c.bench_function("mass_matrix/a465/1", |b| {
        b.iter(|| mass_matrix(&model, &mut data, black_box(&q)).unwrap())
    });
    c.bench_function("gravity/a465/1", |b| {
        b.iter(|| gravity_torque(&model, &mut data, black_box(&q)).unwrap())
    });
    let tau = TABLE2_QDD;
    c.bench_function("forward_dynamics/a465/1", |b| {
        b.iter(|| {
            forward_dynamics(
                &model,
                &mut data,
                black_box(&q),
                black_box(&qd),
                black_box(&tau),
                true,
            )
            .unwrap()
        })
    });
    c.bench_function("rnea_derivatives/a465/1", |b| {
        b.iter(|| {
            rnea_derivatives(
                &model,
                &mut data,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                true,
            )
            .unwrap()
        })
    });
    c.bench_function("linearize/a465/1", |b| {
        b.iter(|| {
            linearize(
                &model,
                &mut data,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                true,
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
