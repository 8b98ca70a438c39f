//! Throughput of every dynamics kernel on the A465, the Panda (when example-robot-data's URDF
//! is installed: `pip install example-robot-data`) and a 60-dof tree:
//! `cargo bench --bench dynamics`. Names are `KERNEL/ROBOT/PATH` with PATH
//! - `one_call`: the one-sample algorithm, one call per sample (the peer of Pinocchio's calls);
//! - `avx512`, `avx2+fma`, `scalar`: the multi-sample kernel of that instruction set (each the
//!   processor has) over a batch, serial;
//! - `parallel`: the batch engine (`perturbid_rs::parallel`) over every core.
//!
//! Every figure is a throughput per sample (criterion's `elem/s`). Forward dynamics compares
//! the articulated-body algorithm (`aba`) with the mass matrix and Cholesky (`crba`).
//! benches/README.md has the numbers and how they compare with Pinocchio.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use perturbid_rs::algorithms::batch::{
    derivatives_batch, linearize_batch, DerivativesOut, LinearizationsOut,
};
use perturbid_rs::algorithms::regressor::joint_torque_regressor;
use perturbid_rs::{
    aba, forward_dynamics_crba, linearize_into, mass_matrix, mass_matrix_batch, parallel,
    regressor_batch, rnea, rnea_batch, rnea_derivatives, Data, Gravity, Isa, LaneData,
    Linearization, Model, States,
};
use std::hint::black_box;
use std::time::Duration;

/// Samples per batch.
const BATCH: usize = 1024;

/// `BATCH` random states (rad, rad/s, rad/s^2), row-major.
fn states(model: &Model) -> [Vec<f64>; 3] {
    let mut rng = common::Rng(7);
    let k = BATCH * model.nv;
    [rng.vector(k, 3.0), rng.vector(k, 2.0), rng.vector(k, 2.0)]
}

fn dynamics(c: &mut Criterion) {
    for (robot, model) in common::speed_robots() {
        let (n, p) = (model.nv, 10 * model.nbodies());
        let [q, qd, qdd] = states(&model);
        let mut data = Data::new(&model);
        let mut group = c.benchmark_group(robot.to_string());
        group
            .throughput(Throughput::Elements(BATCH as u64))
            .sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        let sample = |s: usize| {
            let r = s * n..(s + 1) * n;
            (&q[r.clone()], &qd[r.clone()], &qdd[r])
        };
        // one call per sample, as Pinocchio is called
        group.bench_function("rnea/one_call", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, qdd) = sample(s);
                    rnea(&model, &mut data, q, qd, qdd, Gravity::Included).unwrap();
                    black_box(&data.tau);
                }
            })
        });
        group.bench_function("mass_matrix/one_call", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    mass_matrix(&model, &mut data, sample(s).0).unwrap();
                    black_box(&data.m);
                }
            })
        });
        let mut y = nalgebra::DMatrix::zeros(n, p);
        group.bench_function("regressor/one_call", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, qdd) = sample(s);
                    joint_torque_regressor(
                        &model,
                        &mut data,
                        q,
                        qd,
                        qdd,
                        Gravity::Included,
                        &mut y,
                    )
                    .unwrap();
                    black_box(&y);
                }
            })
        });
        group.bench_function("rnea_derivatives/one_call", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, qdd) = sample(s);
                    rnea_derivatives(&model, &mut data, q, qd, qdd, Gravity::Included).unwrap();
                    black_box(&data.dtau_dq);
                }
            })
        });
        let mut lin = Linearization::zeros(n);
        group.bench_function("linearize/one_call", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, qdd) = sample(s);
                    linearize_into(&model, &mut data, q, qd, qdd, Gravity::Included, &mut lin)
                        .unwrap();
                    black_box(&lin);
                }
            })
        });
        // forward dynamics: qdd as the torques (any torques do)
        group.bench_function("forward_dynamics/aba", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, tau) = sample(s);
                    aba(&model, &mut data, q, qd, tau, Gravity::Included).unwrap();
                    black_box(&data.qdd);
                }
            })
        });
        group.bench_function("forward_dynamics/crba", |b| {
            b.iter(|| {
                for s in 0..BATCH {
                    let (q, qd, tau) = sample(s);
                    forward_dynamics_crba(&model, &mut data, q, qd, tau, Gravity::Included)
                        .unwrap();
                    black_box(&data.qdd);
                }
            })
        });

        // the multi-sample kernels, on every instruction set the processor has
        let mut tau = vec![0.0; BATCH * n];
        let mut mats = vec![vec![0.0; BATCH * n * n]; 5];
        let mut ys = vec![0.0; BATCH * n * p];
        for isa in Isa::available() {
            let mut lanes = LaneData::with_isa(&model, isa).unwrap();
            group.bench_function(format!("rnea/{isa}"), |b| {
                b.iter(|| {
                    rnea_batch(
                        &model,
                        &mut lanes,
                        &q,
                        Some(&qd),
                        Some(&qdd),
                        Gravity::Included,
                        &mut tau,
                    )
                    .unwrap()
                })
            });
            group.bench_function(format!("mass_matrix/{isa}"), |b| {
                b.iter(|| mass_matrix_batch(&model, &mut lanes, &q, &mut mats[0]).unwrap())
            });
            group.bench_function(format!("regressor/{isa}"), |b| {
                b.iter(|| {
                    regressor_batch(
                        &model,
                        &mut lanes,
                        &q,
                        &qd,
                        &qdd,
                        Gravity::Included,
                        &mut ys,
                    )
                    .unwrap()
                })
            });
            group.bench_function(format!("rnea_derivatives/{isa}"), |b| {
                b.iter(|| {
                    let [dq, dv, m, ..] = &mut mats[..] else {
                        unreachable!()
                    };
                    let out = DerivativesOut {
                        tau: &mut tau,
                        dtau_dq: dq,
                        dtau_dv: dv,
                        m,
                    };
                    derivatives_batch(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included, out)
                        .unwrap()
                })
            });
            group.bench_function(format!("linearize/{isa}"), |b| {
                b.iter(|| {
                    let [d, h, g, g_static, _] = &mut mats[..] else {
                        unreachable!()
                    };
                    let out = LinearizationsOut {
                        torque: &mut tau,
                        d,
                        h,
                        g,
                        g_static,
                    };
                    linearize_batch(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included, out)
                        .unwrap()
                })
            });
        }
        // the batch engine over every core
        let mut ws = parallel::Workspace::new(&model);
        let big = 8 * BATCH;
        let [bq, bqd, bqdd] = [&q, &qd, &qdd].map(|x| x.repeat(8));
        let states = States::new(n, &bq, Some(&bqd), Some(&bqdd)).unwrap();
        let mut btau = vec![0.0; big * n];
        group.throughput(Throughput::Elements(big as u64));
        group.bench_function("rnea/parallel", |b| {
            b.iter(|| {
                parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut btau).unwrap()
            })
        });
        group.finish();
    }
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
