//! Throughput of the dynamics core on the built-in A465: `cargo bench --bench dynamics`.
//! Names give the size: `rnea/a465/1` is one call, `batch/rnea/a465/100000` a batch of 10^5
//! samples one at a time (serial, one `Data`), `batch/rnea_lanes/a465/100000` the same batch
//! through the multi-sample kernel (serial too), `batch/parallel_rnea/a465/100000` the batch
//! engine (`perturbid_rs::parallel`: the kernel in chunks over every core, as Python calls it).

use criterion::{criterion_group, criterion_main, Criterion};
use perturbid_rs::algorithms::regressor::joint_torque_regressor;
use perturbid_rs::robots::a465::{TABLE2_Q, TABLE2_QD, TABLE2_QDD};
use perturbid_rs::{
    forward_dynamics, gravity_torque, linearize, mass_matrix, mass_matrix_batch, regressor_batch,
    rnea, rnea_derivatives, rnea_lanes, robots, Data, LaneData, Model,
};
use perturbid_rs::{parallel, Gravity, States};
use std::hint::black_box;

const BATCH: usize = 100_000;

/// `BATCH` states spread around the Table 2 operating point, row-major.
pub fn states(model: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = model.nv;
    let wave = |i: usize, j: usize, f: f64| (f * (i as f64) * 1e-3 + j as f64).sin();
    let q = (0..BATCH * n)
        .map(|x| TABLE2_Q[x % n] + 0.5 * wave(x / n, x % n, 1.0))
        .collect();
    let qd = (0..BATCH * n)
        .map(|x| TABLE2_QD[x % n] + wave(x / n, x % n, 2.0))
        .collect();
    let qdd = (0..BATCH * n)
        .map(|x| TABLE2_QDD[x % n] + wave(x / n, x % n, 3.0))
        .collect();
    (q, qd, qdd)
}

type Kernel = fn(&Model, &mut Data, &[f64], &[f64], &[f64]);

fn dynamics(c: &mut Criterion) {
    let model = robots::builtin("a465").expect("built-in A465");
    let mut data = Data::new(&model);
    let n = model.nv;
    let mut y = nalgebra::DMatrix::zeros(n, 10 * model.nbodies());
    let kernels: [(&str, Kernel); 6] = [
        ("rnea", |m, d, q, qd, qdd| {
            rnea(m, d, q, qd, qdd, Gravity::Included).unwrap()
        }),
        ("mass_matrix", |m, d, q, _, _| mass_matrix(m, d, q).unwrap()),
        ("gravity", |m, d, q, _, _| gravity_torque(m, d, q).unwrap()),
        ("forward_dynamics", |m, d, q, qd, tau| {
            forward_dynamics(m, d, q, qd, tau, Gravity::Included).unwrap()
        }),
        ("rnea_derivatives", |m, d, q, qd, qdd| {
            rnea_derivatives(m, d, q, qd, qdd, Gravity::Included).unwrap()
        }),
        ("linearize", |m, d, q, qd, qdd| {
            linearize(m, d, q, qd, qdd, Gravity::Included).unwrap();
        }),
    ];
    let (bq, bqd, bqdd) = states(&model);
    for (name, f) in kernels {
        c.bench_function(&format!("{name}/a465/1"), |b| {
            b.iter(|| {
                f(
                    &model,
                    &mut data,
                    black_box(&TABLE2_Q),
                    black_box(&TABLE2_QD),
                    black_box(&TABLE2_QDD),
                )
            })
        });
    }
    c.bench_function("regressor/a465/1", |b| {
        b.iter(|| {
            joint_torque_regressor(
                &model,
                &mut data,
                black_box(&TABLE2_Q),
                black_box(&TABLE2_QD),
                black_box(&TABLE2_QDD),
                Gravity::Included,
                &mut y,
            )
            .unwrap()
        })
    });
    let mut group = c.benchmark_group("batch");
    group.sample_size(10);
    for (name, f) in kernels.iter() {
        group.bench_function(format!("{name}/a465/{BATCH}"), |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let r = s * n..(s + 1) * n;
                    f(&model, &mut data, &bq[r.clone()], &bqd[r.clone()], &bqdd[r]);
                }
            })
        });
    }
    // the same batch through the multi-sample kernel (LANES samples side by side)
    let mut lanes = LaneData::new(&model);
    let mut tau = vec![0.0; BATCH * n];
    group.bench_function(format!("rnea_lanes/a465/{BATCH}"), |b| {
        b.iter(|| {
            rnea_lanes(
                &model,
                &mut lanes,
                &bq,
                Some(&bqd),
                Some(&bqdd),
                Gravity::Included,
                &mut tau,
            )
            .unwrap()
        })
    });
    // the batch engine: the same kernels in parallel chunks, states checked once
    let mut workspace = parallel::Workspace::new(&model);
    let states = States::new(n, &bq, Some(&bqd), Some(&bqdd)).unwrap();
    group.bench_function(format!("parallel_rnea/a465/{BATCH}"), |b| {
        b.iter(|| {
            parallel::rnea(&model, &mut workspace, &states, Gravity::Included, &mut tau).unwrap()
        })
    });
    let mut ms = vec![0.0; BATCH * n * n];
    group.bench_function(format!("parallel_mass_matrix/a465/{BATCH}"), |b| {
        b.iter(|| parallel::mass_matrix(&model, &mut workspace, &states, &mut ms).unwrap())
    });
    group.bench_function(format!("mass_matrix_batch/a465/{BATCH}"), |b| {
        b.iter(|| mass_matrix_batch(&model, &mut lanes, &bq, &mut ms).unwrap())
    });
    let mut ys = vec![0.0; BATCH * n * 10 * model.nbodies()];
    group.bench_function(format!("regressor_batch/a465/{BATCH}"), |b| {
        b.iter(|| {
            regressor_batch(
                &model,
                &mut lanes,
                &bq,
                &bqd,
                &bqdd,
                Gravity::Included,
                &mut ys,
            )
            .unwrap()
        })
    });
    group.bench_function(format!("regressor/a465/{BATCH}"), |b| {
        b.iter(|| {
            for s in 0..BATCH {
                let r = s * n..(s + 1) * n;
                joint_torque_regressor(
                    &model,
                    &mut data,
                    &bq[r.clone()],
                    &bqd[r.clone()],
                    &bqdd[r],
                    Gravity::Included,
                    &mut y,
                )
                .unwrap();
            }
        })
    });
    group.finish();
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
