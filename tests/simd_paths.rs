//! Every instruction-set path of the multi-sample kernels ([`Isa`]: AVX-512 with 8 lanes,
//! AVX2+FMA with 4, scalar) against the one-sample algorithms to 1e-12 (relative to the
//! largest entry), on random trees with prismatic and continuous joints, on the A465 and on a
//! mimic coupling, for batch lengths that fill the lanes and leave partial groups. A path the
//! processor lacks cannot run here: its tests say so on stderr and check the refusal instead.

mod common;

use common::{mimic_pair, random_aligned_tree_urdf, random_tree_urdf, Rng};
use nalgebra::DMatrix;
use perturbid_rs::algorithms::batch::{
    derivatives_batch, linearize_batch, regressor_group, DerivativesOut, LinearizationsOut,
};
use perturbid_rs::algorithms::regressor::joint_torque_regressor;
use perturbid_rs::{
    linearize, mass_matrix, mass_matrix_batch, model_from_urdf_str, regressor_batch, rnea,
    rnea_batch, rnea_derivatives, robots, Data, Gravity, Isa, LaneData, LoadOptions, Model,
};
use proptest::prelude::*;

const TOL: f64 = 1e-12;

/// A path: an instruction set; the 8-lane code on AVX2, which checks AVX-512's 8-lane code
/// where the processor has no AVX-512; or an instruction set storing as for a job far larger
/// than the caches (non-temporal stores of whole cache lines: `LaneData::set_job_output`).
#[derive(Clone, Copy, Debug)]
enum Path {
    Isa(Isa),
    EightLanesOnAvx2,
    Streaming(Isa),
}

const PATHS: [Path; 6] = [
    Path::Isa(Isa::Avx512),
    Path::Isa(Isa::Avx2Fma),
    Path::Isa(Isa::Scalar),
    Path::EightLanesOnAvx2,
    Path::Streaming(Isa::Avx512),
    Path::Streaming(Isa::Avx2Fma),
];

/// The lane buffers of `path` for `model`, or `None` (with a note) when the processor lacks it.
fn lanes_for(model: &Model, path: Path) -> Option<LaneData> {
    let isa = match path {
        Path::Isa(isa) | Path::Streaming(isa) => isa,
        Path::EightLanesOnAvx2 => {
            return match LaneData::eight_lanes_on_avx2(model) {
                Ok(l) => {
                    assert_eq!((l.isa(), l.width()), (Isa::Avx2Fma, 8));
                    Some(l)
                }
                Err(e) => {
                    eprintln!("skipped: 8 lanes on AVX2 need AVX2 ({e})");
                    None
                }
            };
        }
    };
    match LaneData::with_isa(model, isa) {
        Ok(mut l) => {
            assert_eq!((l.isa(), l.width()), (isa, isa.lanes()));
            if let Path::Streaming(_) = path {
                l.set_job_output(usize::MAX);
            }
            Some(l)
        }
        Err(e) => {
            assert!(!isa.is_available());
            assert!(e.to_string().contains(isa.name()), "{e}");
            eprintln!("skipped: the {isa} path needs a processor with it ({e})");
            None
        }
    }
}

/// The path's name in messages.
fn describe(path: Path) -> String {
    match path {
        Path::Isa(isa) => isa.name().to_string(),
        Path::EightLanesOnAvx2 => "8 lanes on avx2+fma".into(),
        Path::Streaming(isa) => format!("{isa} with non-temporal stores"),
    }
}

fn close(got: f64, want: f64, scale: f64) -> bool {
    (got - want).abs() <= TOL * scale
}

fn check_rnea(model: &Model, path: Path, rng: &mut Rng, k: usize) {
    let Some(mut lanes) = lanes_for(model, path) else {
        return;
    };
    let isa = describe(path);
    let n = model.nv;
    let (q, qd, qdd) = (
        rng.vector(k * n, 9.0),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 2.0),
    );
    let zeros = vec![0.0; n];
    let mut data = Data::new(model);
    for (with_v, with_a, gravity) in [
        (true, true, Gravity::Included),
        (false, false, Gravity::Included),
        (true, false, Gravity::Excluded),
    ] {
        let mut out = vec![f64::NAN; k * n];
        let (v, a) = (with_v.then_some(&qd[..]), with_a.then_some(&qdd[..]));
        rnea_batch(model, &mut lanes, &q, v, a, gravity, &mut out).unwrap();
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            let vs = if with_v { &qd[r.clone()] } else { &zeros[..] };
            let as_ = if with_a { &qdd[r.clone()] } else { &zeros[..] };
            rnea(model, &mut data, &q[r.clone()], vs, as_, gravity).unwrap();
            let scale = 1.0 + data.tau.amax();
            for j in 0..n {
                assert!(
                    close(out[s * n + j], data.tau[j], scale),
                    "{isa} sample {s} joint {j}: {} vs {}",
                    out[s * n + j],
                    data.tau[j]
                );
            }
        }
    }
}

fn check_mass_matrix(model: &Model, path: Path, rng: &mut Rng, k: usize) {
    let Some(mut lanes) = lanes_for(model, path) else {
        return;
    };
    let isa = describe(path);
    let n = model.nv;
    let q = rng.vector(k * n, 9.0);
    let mut out = vec![f64::NAN; k * n * n];
    mass_matrix_batch(model, &mut lanes, &q, &mut out).unwrap();
    let mut data = Data::new(model);
    for s in 0..k {
        mass_matrix(model, &mut data, &q[s * n..(s + 1) * n]).unwrap();
        let scale = data.m.amax();
        for i in 0..n {
            for j in 0..n {
                let got = out[s * n * n + i * n + j];
                assert!(
                    close(got, data.m[(i, j)], scale),
                    "{isa} sample {s} M[{i}, {j}]: {got} vs {}",
                    data.m[(i, j)]
                );
            }
        }
    }
}

fn check_regressor(model: &Model, path: Path, rng: &mut Rng, k: usize) {
    let Some(mut lanes) = lanes_for(model, path) else {
        return;
    };
    let isa = describe(path);
    let (n, p) = (model.nv, 10 * model.nbodies());
    let (q, qd, qdd) = (
        rng.vector(k * n, 9.0),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 2.0),
    );
    let mut data = Data::new(model);
    let mut y = DMatrix::zeros(n, p);
    for gravity in [Gravity::Included, Gravity::Excluded] {
        let mut out = vec![f64::NAN; k * n * p];
        regressor_batch(model, &mut lanes, &q, &qd, &qdd, gravity, &mut out).unwrap();
        let w = lanes.width();
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            joint_torque_regressor(
                model,
                &mut data,
                &q[r.clone()],
                &qd[r.clone()],
                &qdd[r.clone()],
                gravity,
                &mut y,
            )
            .unwrap();
            // the group kernel, read in place, for the group that starts at this sample
            let g = if s % w == 0 {
                let rows = s * n..(s + w).min(k) * n;
                let g = regressor_group(
                    model,
                    &mut lanes,
                    &q[rows.clone()],
                    &qd[rows.clone()],
                    &qdd[rows],
                    gravity,
                )
                .unwrap();
                assert_eq!(g, (k - s).min(w));
                g
            } else {
                0
            };
            let scale = 1.0 + y.amax();
            for i in 0..n {
                for c in 0..p {
                    let got = out[s * n * p + i * p + c];
                    assert!(
                        close(got, y[(i, c)], scale),
                        "{isa} sample {s} row {i} column {c}: {got} vs {}",
                        y[(i, c)]
                    );
                    if g > 0 {
                        let e = lanes.regressor_entry(0, i, c);
                        assert!(close(e, y[(i, c)], scale), "{isa} group: {e}");
                    }
                }
            }
        }
    }
    // a group larger than the lanes is refused
    let rows = (w_plus_one(&lanes) * n).min(q.len());
    if rows == w_plus_one(&lanes) * n {
        let e = regressor_group(
            model,
            &mut lanes,
            &q[..rows],
            &qd[..rows],
            &qdd[..rows],
            Gravity::Included,
        )
        .unwrap_err();
        assert!(e.to_string().contains("samples"), "{e}");
    }
}

/// `got` (row-major `k x rows x cols`) against the one-sample `want(s)` of every sample.
fn agree(isa: &str, what: &str, got: &[f64], want: &DMatrix<f64>, s: usize) {
    let (r, c) = want.shape();
    let scale = 1.0 + want.amax();
    for i in 0..r {
        for j in 0..c {
            let g = got[s * r * c + i * c + j];
            assert!(
                close(g, want[(i, j)], scale),
                "{isa} {what} sample {s} [{i}, {j}]: {g} vs {}",
                want[(i, j)]
            );
        }
    }
}

fn check_derivatives(model: &Model, path: Path, rng: &mut Rng, k: usize) {
    let Some(mut lanes) = lanes_for(model, path) else {
        return;
    };
    let isa = describe(path);
    let n = model.nv;
    let (q, qd, qdd) = (
        rng.vector(k * n, 9.0),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 2.0),
    );
    let mut data = Data::new(model);
    for gravity in [Gravity::Included, Gravity::Excluded] {
        let mut b = vec![vec![f64::NAN; k * n * n]; 8];
        let mut tau = vec![f64::NAN; k * n];
        let mut torque = vec![f64::NAN; k * n];
        let [dq, dv, m, d, h, g, gs, _] = &mut b[..] else {
            unreachable!()
        };
        let out = DerivativesOut {
            tau: &mut tau,
            dtau_dq: dq,
            dtau_dv: dv,
            m,
        };
        derivatives_batch(model, &mut lanes, &q, &qd, &qdd, gravity, out).unwrap();
        let out = LinearizationsOut {
            torque: &mut torque,
            d,
            h,
            g,
            g_static: gs,
        };
        linearize_batch(model, &mut lanes, &q, &qd, &qdd, gravity, out).unwrap();
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            let x = [&q[r.clone()], &qd[r.clone()], &qdd[r]];
            rnea_derivatives(model, &mut data, x[0], x[1], x[2], gravity).unwrap();
            let t = DMatrix::from_column_slice(1, n, data.tau.as_slice());
            agree(&isa, "tau", &tau, &t, s);
            agree(&isa, "d tau / d q", &b[0], &data.dtau_dq, s);
            agree(&isa, "d tau / d qd", &b[1], &data.dtau_dv, s);
            agree(&isa, "M", &b[2], &data.m, s);
            let lin = linearize(model, &mut data, x[0], x[1], x[2], gravity).unwrap();
            let t = DMatrix::from_column_slice(1, n, lin.torque.as_slice());
            agree(&isa, "T*", &torque, &t, s);
            agree(&isa, "D*", &b[3], &lin.d, s);
            agree(&isa, "H*", &b[4], &lin.h, s);
            agree(&isa, "G*", &b[5], &lin.g, s);
            agree(&isa, "Gs", &b[6], &lin.g_static, s);
        }
    }
}

fn w_plus_one(lanes: &LaneData) -> usize {
    lanes.width() + 1
}

fn models() -> Vec<Model> {
    vec![
        robots::builtin("a465").unwrap(),
        robots::builtin("a465:physical").unwrap(),
        model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap(),
        model_from_urdf_str(&random_tree_urdf(60, 60), "tree60", &LoadOptions::default()).unwrap(),
        model_from_urdf_str(
            &random_aligned_tree_urdf(61, 40),
            "aligned40",
            &LoadOptions::default(),
        )
        .unwrap(),
    ]
}

#[test]
fn every_path_equals_the_one_sample_algorithms_on_fixed_robots() {
    let mut rng = Rng(17);
    for model in models() {
        for path in PATHS {
            for k in [1, 3, 4, 5, 8, 9, 17] {
                check_rnea(&model, path, &mut rng, k);
                check_mass_matrix(&model, path, &mut rng, k);
                check_regressor(&model, path, &mut rng, k);
                check_derivatives(&model, path, &mut rng, k);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    #[test]
    fn every_path_equals_the_one_sample_algorithms_on_random_trees(
        seed in any::<u64>(), nlinks in 1usize..9, k in 1usize..19, aligned in any::<bool>(),
    ) {
        // aligned: most joints take the kernels' shortcut for axis-aligned placements
        let text = if aligned {
            random_aligned_tree_urdf(seed, nlinks)
        } else {
            random_tree_urdf(seed, nlinks)
        };
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        let mut rng = Rng(seed ^ 0xA5A5);
        for path in PATHS {
            check_rnea(&model, path, &mut rng, k);
            check_mass_matrix(&model, path, &mut rng, k);
            check_regressor(&model, path, &mut rng, k);
            check_derivatives(&model, path, &mut rng, k);
        }
    }
}

#[test]
fn buffers_of_another_model_are_refused() {
    let a465 = robots::builtin("a465").unwrap();
    let mimic = model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap();
    let mut lanes = LaneData::new(&mimic);
    let mut out = vec![0.0; 6];
    let e = rnea_batch(
        &a465,
        &mut lanes,
        &[0.0; 6],
        None,
        None,
        Gravity::Included,
        &mut out,
    )
    .unwrap_err();
    assert!(e.to_string().contains("buffers for this model"), "{e}");
    // the same sizes, another tree: a chain of three against three links on the base (the
    // mass matrix kernel keeps the chain's zero pattern in its buffers)
    // (the last joint following `leader` where one is given)
    let tree_following = |parents: [&str; 3], leader: Option<&str>| {
        let mut s = String::from("<robot name=\"t\"><link name=\"base\"/>");
        for (k, p) in parents.iter().enumerate() {
            let mimic = match leader {
                Some(j) if k == 2 => format!("<mimic joint=\"{j}\" multiplier=\"2\"/>"),
                _ => String::new(),
            };
            s += &format!(
                "<link name=\"l{k}\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" \
                 ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial></link>\
                 <joint name=\"j{k}\" type=\"continuous\"><parent link=\"{p}\"/>\
                 <child link=\"l{k}\"/><origin xyz=\"0.1 0 0\"/><axis xyz=\"0 0 1\"/>{mimic}\
                 </joint>"
            );
        }
        let model = model_from_urdf_str(&(s + "</robot>"), "t", &LoadOptions::default());
        model.unwrap()
    };
    let tree = |parents| tree_following(parents, None);
    let (chain, star) = (tree(["base", "l0", "l1"]), tree(["base"; 3]));
    let mut lanes = LaneData::new(&chain);
    let mut m = vec![0.0; 9];
    let e = mass_matrix_batch(&star, &mut lanes, &[0.0; 3], &mut m).unwrap_err();
    assert!(e.to_string().contains("other parents"), "{e}");
    mass_matrix_batch(&chain, &mut lanes, &[0.0; 3], &mut m).unwrap();
    // the same sizes and tree, the bodies on other degrees of freedom: a chain of three whose
    // last joint follows the first, against one whose last follows the second (the regressor's
    // zero pattern is by degree of freedom)
    let follower = |leader| tree_following(["base", "l0", "l1"], Some(leader));
    let (first, second) = (follower("j0"), follower("j1"));
    assert_eq!((first.nv, second.nv), (2, 2));
    let mut lanes = LaneData::new(&first);
    let mut y = vec![0.0; 2 * 30];
    let e = regressor_batch(
        &second,
        &mut lanes,
        &[0.1, 0.2],
        &[0.0; 2],
        &[0.0; 2],
        Gravity::Included,
        &mut y,
    )
    .unwrap_err();
    assert!(e.to_string().contains("degrees of freedom"), "{e}");
}

#[test]
fn the_detected_path_is_the_widest_available() {
    let best = Isa::detect();
    assert_eq!(Some(&best), Isa::available().first());
    assert_eq!(LaneData::new(&robots::builtin("a465").unwrap()).isa(), best);
    eprintln!(
        "this processor runs the {best} path ({} lanes)",
        best.lanes()
    );
}

#[test]
fn a_kernel_vouches_for_its_output_only_when_every_value_is_finite() {
    // the batch engine skips reading back what a kernel checked in registers: the flag must be
    // true on finite output and false as soon as one value is not (or the path cannot tell)
    let model = robots::builtin("a465").unwrap();
    let (n, p) = (model.nv, 10 * model.nbodies());
    let k = 13;
    let q = vec![0.3; k * n];
    let mut qd = vec![0.2; k * n];
    let qdd = vec![0.1; k * n];
    for path in PATHS {
        let Some(mut lanes) = lanes_for(&model, path) else {
            continue;
        };
        let vector_path = lanes.isa() != Isa::Scalar;
        let mut y = vec![0.0; k * n * p];
        regressor_batch(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included, &mut y).unwrap();
        assert_eq!(lanes.wrote_finite(), vector_path, "{}", describe(path));
        assert!(y.iter().all(|v| v.is_finite()));
        // one overflowing sample, in the last (partial) group and in a full one
        for bad in [k - 1, 2] {
            qd[bad * n + 1] = 1e200;
            regressor_batch(&model, &mut lanes, &q, &qd, &qdd, Gravity::Included, &mut y).unwrap();
            assert!(!lanes.wrote_finite(), "{} sample {bad}", describe(path));
            assert!(y.iter().any(|v| !v.is_finite()));
            qd[bad * n + 1] = 0.2;
        }
        // the torques too, on a finite and an overflowing sample
        let mut tau = vec![0.0; k * n];
        for (bad, vouched) in [(None, vector_path), (Some(k - 1), false), (Some(3), false)] {
            if let Some(s) = bad {
                qd[s * n + 2] = 1e200;
            }
            let (v, a) = (Some(&qd[..]), Some(&qdd[..]));
            let done = rnea_batch(&model, &mut lanes, &q, v, a, Gravity::Included, &mut tau);
            qd.iter_mut().for_each(|v| *v = 0.2);
            if !vector_path && bad.is_some() {
                // the one-sample algorithm refuses the overflow itself
                assert!(done.is_err());
                continue;
            }
            done.unwrap();
            assert_eq!(lanes.wrote_finite(), vouched, "{} {bad:?}", describe(path));
            assert_eq!(tau.iter().all(|v| v.is_finite()), bad.is_none());
        }
        // the mass matrix of the A465 (which has an armature, added after the rows) too
        let mut m = vec![0.0; k * n * n];
        mass_matrix_batch(&model, &mut lanes, &q, &mut m).unwrap();
        assert_eq!(lanes.wrote_finite(), vector_path, "{}", describe(path));
        lanes.forget_finite();
        assert!(!lanes.wrote_finite());
    }
}

#[test]
fn bodies_are_related_when_one_is_an_ancestor_of_the_other_and_only_those_pair_in_m() {
    // the mass matrix kernels write the pairs of unrelated bodies as zeros without computing
    // them: that must be what the one-sample algorithm gives there
    let mut rng = Rng(5);
    for model in models() {
        let nb = model.nbodies();
        let ancestors = |mut b: usize| {
            let mut out = vec![b];
            while let Some(p) = model.bodies[b].parent {
                out.push(p);
                b = p;
            }
            out
        };
        let mut data = Data::new(&model);
        mass_matrix(&model, &mut data, &rng.vector(model.nv, 3.0)).unwrap();
        for i in 0..nb {
            for j in 0..nb {
                let want = ancestors(i).contains(&j) || ancestors(j).contains(&i);
                assert_eq!(model.related(i, j), want, "bodies {i}, {j}");
                if !want && !model.coupled {
                    assert_eq!(data.m[(i, j)], 0.0, "M[{i}, {j}] of unrelated bodies");
                }
            }
        }
    }
}
