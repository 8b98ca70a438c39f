//! The batch engine (`perturbid_rs::parallel`) against the one-sample algorithms, on batches
//! large enough to run in parallel chunks (with a partial last chunk and a partial lane group),
//! and its errors naming the sample of the whole batch.

mod common;

use common::{mimic_pair, random_tree_urdf, Rng};
use perturbid_rs::parallel::{self, LinearizationsOut, Workspace, PARALLEL_BATCH, PARALLEL_CHUNK};
use perturbid_rs::{
    forward_dynamics, linearize, mass_matrix, model_from_urdf_str, rnea, robots, Data, Error,
    Gravity, LoadOptions, Model, States,
};

/// `k` random states of `model`, row-major.
fn random_states(model: &Model, k: usize, seed: u64) -> [Vec<f64>; 3] {
    let mut rng = Rng(seed);
    let mut draw = |scale: f64| {
        (0..k * model.nv)
            .map(|_| rng.uniform(-scale, scale))
            .collect()
    };
    [draw(3.0), draw(2.0), draw(5.0)]
}

fn models() -> Vec<Model> {
    let mut out = vec![robots::builtin("a465").unwrap()];
    for urdf in [random_tree_urdf(7, 9), mimic_pair(true)] {
        out.push(model_from_urdf_str(&urdf, "<test>", &LoadOptions::default()).unwrap());
    }
    out
}

fn close(a: &[f64], b: &[f64]) -> bool {
    let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-11 * scale)
}

#[test]
fn every_batch_algorithm_equals_its_one_sample_version() {
    let k = PARALLEL_BATCH + PARALLEL_CHUNK / 2 + 3; // parallel, partial chunk and lane group
    for model in models() {
        let n = model.nv;
        let [q, qd, qdd] = random_states(&model, k, 11);
        let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
        let mut ws = Workspace::new(&model);
        let mut data = Data::new(&model);
        let row = |x: &[f64], s: usize| x[s * n..(s + 1) * n].to_vec();

        let mut tau = vec![f64::NAN; k * n];
        parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap();
        let mut mm = vec![f64::NAN; k * n * n];
        parallel::mass_matrix(&model, &mut ws, &states, &mut mm).unwrap();
        let mut qdd_out = vec![f64::NAN; k * n];
        let fd_states = States::new(n, &q, Some(&qd), None).unwrap();
        parallel::forward_dynamics(
            &model,
            &mut ws,
            &fd_states,
            &tau,
            Gravity::Included,
            &mut qdd_out,
        )
        .unwrap();
        let mut parts = [(); 5].map(|_| vec![f64::NAN; k * n * n]);
        let [t, d, h, g, gs] = &mut parts;
        let out = LinearizationsOut {
            torque: &mut t[..k * n],
            d,
            h,
            g,
            g_static: gs,
        };
        parallel::linearize(&model, &mut ws, &states, Gravity::Excluded, out).unwrap();

        for s in (0..k).step_by(97).chain([k - 1]) {
            rnea(
                &model,
                &mut data,
                &row(&q, s),
                &row(&qd, s),
                &row(&qdd, s),
                Gravity::Included,
            )
            .unwrap();
            assert!(
                close(&row(&tau, s), data.tau.as_slice()),
                "rnea, sample {s}"
            );
            mass_matrix(&model, &mut data, &row(&q, s)).unwrap();
            let m: Vec<f64> = data.m.transpose().iter().copied().collect();
            assert!(
                close(&mm[s * n * n..(s + 1) * n * n], &m),
                "mass matrix, sample {s}"
            );
            forward_dynamics(
                &model,
                &mut data,
                &row(&q, s),
                &row(&qd, s),
                &row(&tau, s),
                Gravity::Included,
            )
            .unwrap();
            // forward dynamics inverts the inverse dynamics
            assert!(
                close(&row(&qdd_out, s), &row(&qdd, s)),
                "forward dynamics, sample {s}"
            );
            let lin = linearize(
                &model,
                &mut data,
                &row(&q, s),
                &row(&qd, s),
                &row(&qdd, s),
                Gravity::Excluded,
            )
            .unwrap();
            assert!(
                close(&parts[0][s * n..(s + 1) * n], lin.torque.as_slice()),
                "T*, sample {s}"
            );
            for (b, m) in [&lin.d, &lin.h, &lin.g, &lin.g_static].iter().enumerate() {
                let m: Vec<f64> = m.transpose().iter().copied().collect();
                assert!(
                    close(&parts[b + 1][s * n * n..(s + 1) * n * n], &m),
                    "part {b}, sample {s}"
                );
            }
        }
    }
}

#[test]
fn missing_velocities_and_accelerations_are_zeros() {
    let model = robots::builtin("a465").unwrap();
    let n = model.nv;
    let k = 9;
    let [q, ..] = random_states(&model, k, 3);
    let zeros = vec![0.0; k * n];
    let mut ws = Workspace::new(&model);
    let (mut a, mut b) = (vec![0.0; k * n], vec![0.0; k * n]);
    let states = States::new(n, &q, None, None).unwrap();
    parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut a).unwrap();
    let full = States::new(n, &q, Some(&zeros), Some(&zeros)).unwrap();
    parallel::rnea(&model, &mut ws, &full, Gravity::Included, &mut b).unwrap();
    assert!(close(&a, &b));
}

#[test]
fn errors_name_the_sample_of_the_whole_batch() {
    let model = robots::builtin("a465").unwrap();
    let n = model.nv;
    let k = PARALLEL_BATCH + 10;
    let [mut q, qd, qdd] = random_states(&model, k, 5);
    q[4100 * n + 2] = f64::NAN;
    match States::new(n, &q, Some(&qd), Some(&qdd)) {
        Err(Error::NonFiniteInput {
            argument,
            index: 2,
            value,
        }) => {
            assert_eq!(argument, "q[4100]");
            assert!(value.is_nan());
        }
        other => panic!("expected a non-finite q[4100], got {other:?}"),
    }
    assert!(States::single(n, &q[..n], None, None).is_ok());
    let e = States::single(n, &q[4100 * n..4101 * n], None, None).unwrap_err();
    assert!(e.to_string().starts_with("q: entry 2 is NaN"), "{e}");
    // shapes: a wrong output length and a model of other joints are refused, not written
    let [q, qd, qdd] = random_states(&model, k, 6);
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut ws = Workspace::new(&model);
    let mut short = vec![0.0; k * n - 1];
    let e = parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut short).unwrap_err();
    assert!(e.to_string().contains("tau"), "{e}");
    let other = States::new(3, &q[..3 * 4], None, None).unwrap();
    let e = parallel::mass_matrix(&model, &mut ws, &other, &mut [0.0; 4 * 36]).unwrap_err();
    assert!(e.to_string().contains("6 joints per sample"), "{e}");
    // a torque that is not finite, named at its sample
    let mut tau = vec![0.0; k * n];
    tau[4103 * n] = f64::INFINITY;
    let e = parallel::forward_dynamics(
        &model,
        &mut ws,
        &states,
        &tau,
        Gravity::Included,
        &mut vec![0.0; k * n],
    )
    .unwrap_err();
    assert!(e.to_string().contains("tau[4103]"), "{e}");
}

#[test]
fn a_regressor_group_equals_the_one_sample_regressor() {
    use perturbid_rs::algorithms::batch::{regressor_group, LaneData};
    use perturbid_rs::algorithms::regressor::joint_torque_regressor;
    for model in models() {
        let n = model.nv;
        let mut lanes = LaneData::new(&model);
        let k = lanes.width().min(3);
        let [q, qd, qdd] = random_states(&model, k, 21);
        let g = regressor_group(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included).unwrap();
        assert_eq!(g, k);
        let mut data = Data::new(&model);
        let mut y = nalgebra::DMatrix::zeros(n, 10 * model.nbodies());
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            joint_torque_regressor(
                &model,
                &mut data,
                &q[r.clone()],
                &qd[r.clone()],
                &qdd[r],
                Gravity::Included,
                &mut y,
            )
            .unwrap();
            let scale = y.amax().max(1.0);
            for (j, p) in (0..n).flat_map(|j| (0..y.ncols()).map(move |p| (j, p))) {
                assert!((lanes.regressor_entry(s, j, p) - y[(j, p)]).abs() <= 1e-12 * scale);
            }
        }
        // more samples than lanes are refused, not truncated
        let [q, qd, qdd] = random_states(&model, lanes.width() + 1, 22);
        assert!(regressor_group(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included).is_err());
    }
}

#[test]
fn outputs_past_the_caches_are_the_same_bits_as_small_calls_write() {
    // past 16 MB of output (a job of the batch engine, or one kernel call) the AVX-512 kernels
    // store whole cache lines non-temporally: the values must be those of the same kernels
    // called on 8 samples at a time, bit for bit (elsewhere the test holds trivially)
    use perturbid_rs::{mass_matrix_batch, regressor_batch, LaneData};
    let tree = model_from_urdf_str(&random_tree_urdf(60, 60), "tree60", &LoadOptions::default());
    let jobs = [
        // the engine's parallel chunks (2.9 MB each) of a 24 MB job (no chunk of fewer samples
        // than lanes: those go through the one-sample algorithms) and the mass matrix's serial
        // 2.4 MB; the tree's serial 22 MB of regressor and 20 MB of mass matrices
        (
            robots::builtin("a465").unwrap(),
            2 * PARALLEL_BATCH + 8,
            2 * PARALLEL_BATCH + 8,
        ),
        (tree.unwrap(), 77, 700),
    ];
    for (model, k, k_m) in jobs {
        let (n, p) = (model.nv, 10 * model.nbodies());
        let [q, qd, qdd] = random_states(&model, k.max(k_m), 31);
        let mut ws = Workspace::new(&model);
        let r = ..k * n;
        let states = States::new(n, &q[r], Some(&qd[r]), Some(&qdd[r])).unwrap();
        let mut y = vec![f64::NAN; k * n * p];
        parallel::regressor(&model, &mut ws, &states, Gravity::Included, &mut y).unwrap();
        let mut m = vec![f64::NAN; k_m * n * n];
        let many = States::new(n, &q[..k_m * n], None, None).unwrap();
        parallel::mass_matrix(&model, &mut ws, &many, &mut m).unwrap();

        let mut lanes = LaneData::new(&model);
        let (mut y8, mut m8) = (vec![f64::NAN; y.len()], vec![f64::NAN; m.len()]);
        for (c, yc) in y8.chunks_mut(8 * n * p).enumerate() {
            let r = c * 8 * n..((c + 1) * 8 * n).min(k * n);
            let x = [&q[r.clone()], &qd[r.clone()], &qdd[r]];
            regressor_batch(&model, &mut lanes, x[0], x[1], x[2], Gravity::Included, yc).unwrap();
        }
        for (c, mc) in m8.chunks_mut(8 * n * n).enumerate() {
            let r = c * 8 * n..((c + 1) * 8 * n).min(k_m * n);
            mass_matrix_batch(&model, &mut lanes, &q[r], mc).unwrap();
        }
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&y, &y8), "regressor of {k} samples");
        assert!(same(&m, &m8), "mass matrix of {k_m} samples");
    }
}

#[test]
fn one_workspace_serves_every_model_and_its_clones_too() {
    // the engine's threads keep their buffers in the caller's workspace between calls: one made
    // for another model (other sizes, or the same sizes and another tree) must not be used
    let k = PARALLEL_BATCH + 5;
    let tree = |seed| {
        model_from_urdf_str(
            &random_tree_urdf(seed, 9),
            "<test>",
            &LoadOptions::default(),
        )
        .unwrap()
    };
    let mut list = models();
    list.extend([tree(8), tree(9), robots::builtin("a465").unwrap()]);
    let mut shared = Workspace::new(&list[0]);
    for (i, model) in list.iter().enumerate() {
        let n = model.nv;
        let [q, qd, qdd] = random_states(model, k, 40 + i as u64);
        let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
        let mut fresh = Workspace::new(model);
        let run = |ws: &mut Workspace| {
            let mut tau = vec![f64::NAN; k * n];
            parallel::rnea(model, ws, &states, Gravity::Included, &mut tau).unwrap();
            let mut mm = vec![f64::NAN; k * n * n];
            parallel::mass_matrix(model, ws, &states, &mut mm).unwrap();
            let mut qdd_out = vec![f64::NAN; k * n];
            let fd = States::new(n, &q, Some(&qd), None).unwrap();
            parallel::forward_dynamics(model, ws, &fd, &tau, Gravity::Included, &mut qdd_out)
                .unwrap();
            [tau, mm, qdd_out]
        };
        let expected = run(&mut fresh);
        // the shared workspace's own buffers are for the first model only: its parallel
        // threads' must be remade, and a clone starts without them
        let got = run(&mut shared);
        let cloned = run(&mut fresh.clone());
        for (what, e) in expected.iter().enumerate() {
            assert!(e.iter().all(|v| v.is_finite()), "model {i}, output {what}");
            assert_eq!(e, &got[what], "model {i}, output {what}, shared workspace");
            assert_eq!(
                e, &cloned[what],
                "model {i}, output {what}, cloned workspace"
            );
        }
    }
}
