//! Shared helpers of the Rust integration tests: random URDF trees and numeric comparisons.
#![allow(dead_code)]

use nalgebra::DMatrix;

pub mod gain_logs;
pub mod temp_dir;

/// A deterministic pseudo-random generator (splitmix64) so helpers need no extra crate.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn vector(&mut self, n: usize, scale: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(-scale, scale)).collect()
    }
}

/// A random kinematic tree as URDF text: `nlinks` links below a massless base, each attached to
/// a random earlier link by a revolute, continuous, prismatic or fixed joint (the first joint
/// always moves), with random origins, axes and physically valid inertias.
pub fn random_tree_urdf(seed: u64, nlinks: usize) -> String {
    tree_urdf(seed, nlinks, false)
}

/// As [`random_tree_urdf`], with joint axes along +-x, +-y or +-z and joint origins turned by
/// multiples of pi/2 (as most robots' URDFs are: the kernels' shortcut for such joints), every
/// fifth joint left general.
pub fn random_aligned_tree_urdf(seed: u64, nlinks: usize) -> String {
    tree_urdf(seed, nlinks, true)
}

fn tree_urdf(seed: u64, nlinks: usize, aligned: bool) -> String {
    let mut r = Rng(seed);
    let mut s = String::from("<robot name=\"random\">\n  <link name=\"base\"/>\n");
    for k in 1..=nlinks {
        // principal moments from a random mass distribution: always a valid rigid body
        let (a, b, c) = (
            r.uniform(0.01, 0.2),
            r.uniform(0.01, 0.2),
            r.uniform(0.01, 0.2),
        );
        s += &format!(
            "  <link name=\"l{k}\"><inertial><origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><mass value=\"{}\"/>\
             <inertia ixx=\"{}\" ixy=\"0\" ixz=\"0\" iyy=\"{}\" iyz=\"0\" izz=\"{}\"/></inertial></link>\n",
            r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2),
            r.uniform(-3.0, 3.0), r.uniform(-1.5, 1.5), r.uniform(-3.0, 3.0),
            r.uniform(0.2, 3.0), b + c, a + c, a + b
        );
    }
    for k in 1..=nlinks {
        let parent = if k == 1 {
            "base".to_string()
        } else {
            format!("l{}", r.below(k))
        };
        let parent = if parent == "l0" {
            "base".to_string()
        } else {
            parent
        };
        let kind = if k == 1 {
            "revolute"
        } else {
            ["revolute", "continuous", "prismatic", "fixed", "revolute"][r.below(5)]
        };
        let xyz = [
            r.uniform(-0.3, 0.3),
            r.uniform(-0.3, 0.3),
            r.uniform(0.0, 0.4),
        ];
        let (rpy, axis) = if aligned && r.below(5) != 0 {
            // quarter turns and a signed unit axis; some translations along one axis only
            let quarter = std::f64::consts::FRAC_PI_2;
            let rpy = [0; 3].map(|_| quarter * (r.below(4) as f64 - 1.0));
            let mut axis = [0.0; 3];
            axis[r.below(3)] = if r.below(2) == 0 { 1.0 } else { -1.0 };
            (rpy, axis)
        } else {
            (
                [
                    r.uniform(-3.0, 3.0),
                    r.uniform(-1.5, 1.5),
                    r.uniform(-3.0, 3.0),
                ],
                [
                    r.uniform(-1.0, 1.0),
                    r.uniform(-1.0, 1.0),
                    r.uniform(0.2, 1.0),
                ],
            )
        };
        let xyz = if aligned && r.below(2) == 0 {
            let j = r.below(3);
            [0, 1, 2].map(|i| if i == j { xyz[i] } else { 0.0 })
        } else {
            xyz
        };
        s += &format!(
            "  <joint name=\"j{k}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"l{k}\"/>\
             <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><axis xyz=\"{} {} {}\"/>\
             <limit lower=\"-2\" upper=\"2\" effort=\"100\" velocity=\"3\"/></joint>\n",
            xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2], axis[0], axis[1], axis[2]
        );
    }
    s + "</robot>\n"
}

/// The paper's operating point (Table 2).
pub fn table2() -> perturbid_rs::OperatingPoint {
    use perturbid_rs::robots::a465;
    perturbid_rs::OperatingPoint::new(
        a465::TABLE2_Q.to_vec(),
        a465::TABLE2_QD.to_vec(),
        a465::TABLE2_QDD.to_vec(),
    )
    .unwrap()
}

/// The A465 at Table 2's point, planned by default and simulated with 0.01 N m of torque
/// noise: the robot, the point, the plan, the recordings and the local model identified from
/// them by default.
pub struct Table2Local {
    pub model: perturbid_rs::Model,
    pub op: perturbid_rs::OperatingPoint,
    pub plan: perturbid_rs::local::Plan,
    pub recs: Vec<perturbid_rs::Recording>,
    pub local: perturbid_rs::local::LocalModel,
}

pub fn table2_local() -> Table2Local {
    use perturbid_rs::local::{identify_local, plan_experiments, IdentifyOptions, PlanOptions};
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let mut sim = perturbid_rs::SimulationOptions::new(&model);
    sim.torque_noise = vec![0.01; model.nv];
    let recs = perturbid_rs::simulate_plan(&model, &plan, &sim).unwrap();
    let local = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    Table2Local {
        model,
        op,
        plan,
        recs,
        local,
    }
}

/// The robot's own linearisation at `op`, gravity included.
pub fn linearized(
    model: &perturbid_rs::Model,
    op: &perturbid_rs::OperatingPoint,
) -> perturbid_rs::Linearization {
    let mut data = perturbid_rs::Data::new(model);
    perturbid_rs::linearize(
        model,
        &mut data,
        &op.q,
        &op.qd,
        &op.qdd,
        perturbid_rs::Gravity::Included,
    )
    .unwrap()
}

/// The A465 (the paper's parameters), Table 2, the orthogonal plan there, and the robot's own
/// linearisation at it (gravity included): the truth a rehearsed identification is held to.
pub fn a465_orthogonal_at_table2() -> (
    perturbid_rs::Model,
    perturbid_rs::OperatingPoint,
    perturbid_rs::Plan,
    perturbid_rs::Linearization,
) {
    use perturbid_rs::local::{plan_experiments, Design};
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let op = table2();
    let options = perturbid_rs::PlanOptions {
        design: Design::Orthogonal,
        ..perturbid_rs::PlanOptions::default()
    };
    let plan = plan_experiments(&model, &op, &options).unwrap();
    let truth = linearized(&model, &op);
    (model, op, plan, truth)
}

/// |a - b| / |b| (Frobenius norms).
pub fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

/// The matrix of an identified estimate that must exist.
pub fn mat(e: &Option<perturbid_rs::local::Estimate>) -> &DMatrix<f64> {
    &e.as_ref().unwrap().matrix
}

/// max |a - b| / max(1, max |b|).
pub fn rel_err(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    let scale = b.amax().max(1.0);
    (a - b).amax() / scale
}

/// A planar chain with a coupled joint: `b` follows `a` with multiplier 2 and offset 0.1.
pub fn mimic_pair(mimic: bool) -> String {
    let mimic_tag = if mimic {
        r#"<mimic joint="a" multiplier="2" offset="0.1"/>"#
    } else {
        ""
    };
    format!(
        r#"<robot name="m">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.3 0 0"/><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0.1 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.015"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0.1 0 0.05"/><mass value="0.5"/><inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="b" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.6 0 0"/><axis xyz="0 1 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/>{mimic_tag}</joint>
  <joint name="c" type="prismatic"><parent link="l2"/><child link="l3"/><origin xyz="0.4 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
</robot>"#
    )
}

/// The A465 (physical) with an armature on every joint: joints 1-3 through `<dynamics
/// armature>`, joints 4-6 through Drake `<transmission>` elements.
pub fn a465_with_armature() -> perturbid_rs::Model {
    let text = perturbid_rs::robots::a465::urdf("physical").unwrap();
    let mut text = text.replace(
        "<robot name=\"a465_physical\"",
        "<robot xmlns:drake=\"http://drake.mit.edu\" name=\"a465_physical\"",
    );
    for (j, a) in [(1, 0.8), (2, 0.5), (3, 0.3)] {
        let tag = format!("<joint name=\"joint{j}\" type=\"revolute\">");
        text = text.replace(&tag, &format!("{tag}\n    <dynamics armature=\"{a}\"/>"));
    }
    let mut transmissions = String::new();
    for (j, rotor, ratio) in [(4, 1e-5, 101.0), (5, 2e-5, 100.0), (6, 1e-5, 101.0)] {
        transmissions.push_str(&format!(
            "  <transmission type=\"SimpleTransmission\" name=\"t{j}\">\n    <joint name=\"joint{j}\"/>\n    <actuator name=\"m{j}\"><drake:rotor_inertia value=\"{rotor}\"/><drake:gear_ratio value=\"{ratio}\"/></actuator>\n  </transmission>\n"
        ));
    }
    text = text.replace("</robot>", &format!("{transmissions}</robot>"));
    perturbid_rs::model_from_urdf_str(
        &text,
        "a465+armature",
        &perturbid_rs::LoadOptions::default(),
    )
    .unwrap()
}

/// A random operating point within 0.8 of the position limits.
pub fn random_op(model: &perturbid_rs::Model, rng: &mut Rng) -> perturbid_rs::OperatingPoint {
    let n = model.nv;
    let q = (0..n)
        .map(|j| {
            let l = &model.limits[j];
            rng.uniform(0.8 * l.lower, 0.8 * l.upper)
        })
        .collect();
    perturbid_rs::OperatingPoint::new(q, rng.vector(n, 0.5), rng.vector(n, 1.0)).unwrap()
}

/// An exact local model at `op` (what noise-free data give for T*, D*, H*).
pub fn exact_local(
    model: &perturbid_rs::Model,
    op: &perturbid_rs::OperatingPoint,
) -> perturbid_rs::local::LocalModel {
    let n = model.nv;
    let lin = perturbid_rs::linearize(
        model,
        &mut perturbid_rs::Data::new(model),
        &op.q,
        &op.qd,
        &op.qdd,
        perturbid_rs::Gravity::Included,
    )
    .unwrap();
    let est = |m: &DMatrix<f64>| {
        Some(perturbid_rs::local::Estimate {
            matrix: m.clone(),
            cond: 1.0,
            residual_rms: vec![0.0; n],
            stderr: DMatrix::from_element(n, n, 1e-9),
            crossings: 2 * n,
            correlation: vec![DMatrix::identity(n, n); n],
        })
    };
    perturbid_rs::local::LocalModel {
        format: <perturbid_rs::local::LocalModel as perturbid_rs::Document>::tag(),
        robot: model.name.clone(),
        joint_names: model.joint_names.clone(),
        op: op.clone(),
        planned_op: op.clone(),
        estimator: perturbid_rs::local::Estimator::Separated,
        torque: lin.torque.as_slice().to_vec(),
        torque_stderr: vec![1e-9; n],
        d: est(&lin.d),
        h: est(&lin.h),
        g: None,
        g_static: None,
        combined: None,
        coulomb: None,
        perturbations: None,
        diagnostics: Default::default(),
        drive_gains: None,
        miss: None,
    }
}

/// The example-robot-data Panda URDF, found through the Python installation that the test
/// script sets up (`pip install example-robot-data`); `None` when it is not installed.
pub fn panda_urdf() -> Option<std::path::PathBuf> {
    let out =
        std::process::Command::new(std::env::var("PYTHON").unwrap_or_else(|_| "python3".into()))
            .args([
                "-c",
                "import sysconfig; print(sysconfig.get_paths()['purelib'])",
            ])
            .output()
            .ok()?;
    let purelib = String::from_utf8(out.stdout).ok()?;
    let path = std::path::Path::new(purelib.trim())
        .join("cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf");
    path.is_file().then_some(path)
}

/// That Panda with its fingers locked (7 dofs; the second finger mimics the first and is held
/// with it); `None` when the URDF is not installed.
pub fn panda_model() -> Option<perturbid_rs::Model> {
    let mut options = perturbid_rs::LoadOptions::default();
    options.lock.insert("panda_finger_joint1".to_string(), 0.0);
    perturbid_rs::model_from_urdf_file(&panda_urdf()?, &options).ok()
}

/// The robots of the speed comparisons: the A465, the Panda when installed, and the 60-dof
/// tree `benches/tree60.urdf` (the one benches/compare_pinocchio.py measures against
/// Pinocchio).
pub fn speed_robots() -> Vec<(&'static str, perturbid_rs::Model)> {
    let mut out = vec![("a465", perturbid_rs::robots::builtin("a465").unwrap())];
    match panda_model() {
        Some(m) => out.push(("panda", m)),
        None => eprintln!(
            "skipped the Panda: example-robot-data's panda.urdf is not installed \
             (pip install example-robot-data)"
        ),
    }
    let tree = include_str!("../../benches/tree60.urdf");
    let options = perturbid_rs::LoadOptions::default();
    out.push((
        "tree60",
        perturbid_rs::model_from_urdf_str(tree, "tree60", &options).unwrap(),
    ));
    out
}

/// The real Panda log of Gaz et al. (2019) beside the repository
/// (`../shared/data/panda-gaz2019/excitation.csv`, docs/data.md) as a recording of its 7
/// joints with `qd`; `None`, saying on stderr that the test is skipped, when it is not there.
pub fn panda_log() -> Option<perturbid_rs::Recording> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/panda-gaz2019/excitation.csv");
    let Ok(text) = std::fs::read_to_string(&path) else {
        eprintln!(
            "SKIPPED: {} is not there (the real Panda log lies beside the repository; see docs/data.md)",
            path.display()
        );
        return None;
    };
    let (mut t, mut q, mut qd, mut tau) = (vec![], vec![], vec![], vec![]);
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        t.push(v[0]);
        q.extend_from_slice(&v[1..8]);
        qd.extend_from_slice(&v[8..15]);
        tau.extend_from_slice(&v[15..22]);
    }
    Some(perturbid_rs::Recording::new("panda", 7, t, q, tau, Some(qd), None).unwrap())
}

/// An edit of a saved document, and what the error of loading the edited one says.
pub type RefusedEdit<'a> = (fn(&mut serde_json::Value), &'a str);

/// Each of `edits` applied to the saved document `value` makes loading it as a `T` fail with
/// an error that contains the edit's text.
pub fn refused_on_load<T: perturbid_rs::Document + std::fmt::Debug>(
    value: &serde_json::Value,
    edits: &[RefusedEdit<'_>],
) {
    for (edit, says) in edits {
        let mut bad = value.clone();
        edit(&mut bad);
        let e = T::from_json(&bad.to_string()).unwrap_err().to_string();
        assert!(e.contains(says), "{e}");
    }
}

/// A 5-harmonic excitation of the A465 at 0.1 Hz about [0.2, 0.3, -0.4, 0.1, 0.5, -0.2] rad,
/// its sine and cosine coefficients drawn uniformly within +-0.12 from `rng`.
pub fn a465_excitation(rng: &mut Rng) -> perturbid_rs::trajectory::FourierTrajectory {
    let a = DMatrix::from_fn(6, 5, |_, _| rng.uniform(-0.12, 0.12));
    let b = DMatrix::from_fn(6, 5, |_, _| rng.uniform(-0.12, 0.12));
    perturbid_rs::trajectory::FourierTrajectory::new(
        2.0 * std::f64::consts::PI * 0.1,
        vec![0.2, 0.3, -0.4, 0.1, 0.5, -0.2],
        a,
        b,
    )
    .unwrap()
}

/// The torques of `model` along `s` (row-major, N m) with gravity, viscous (0.3 N m s/rad)
/// and Coulomb (0.8 N m, none at exactly zero speed) friction, and `noise(rng)` added to each.
pub fn torques_with_friction(
    model: &perturbid_rs::Model,
    s: &perturbid_rs::trajectory::Samples,
    rng: &mut Rng,
    noise: impl Fn(&mut Rng) -> f64,
) -> Vec<f64> {
    use perturbid_rs::{parallel, Gravity, States};
    let states = States::new(s.n, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let mut tau = vec![0.0; s.q.len()];
    parallel::rnea(
        model,
        &mut parallel::Workspace::new(model),
        &states,
        Gravity::Included,
        &mut tau,
    )
    .unwrap();
    for (i, x) in tau.iter_mut().enumerate() {
        let v = s.qd[i];
        *x += 0.3 * v + 0.8 * v.signum() * f64::from(v != 0.0) + noise(rng);
    }
    tau
}

/// Samples of an A465 excitation (5 harmonics, 12 s at 1 kHz; rad, rad/s, rad/s^2, row-major)
/// and the torques (N m) of a robot whose parameters are the paper's (`kinsheel2010`), with
/// viscous and Coulomb friction and 0.03 N m of noise.
pub struct A465Log {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
}

/// The log of [`A465Log`] (seed 9).
pub fn a465_log() -> A465Log {
    let truth = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let mut rng = Rng(9);
    let traj = a465_excitation(&mut rng);
    let t: Vec<f64> = (0..12_000).map(|i| i as f64 * 1e-3).collect();
    let s = traj.sample(&t);
    let tau = torques_with_friction(&truth, &s, &mut rng, |r| 0.03 * r.uniform(-1.7, 1.7));
    A465Log {
        q: s.q,
        qd: s.qd,
        qdd: s.qdd,
        tau,
    }
}

/// `log` fitted by the direct method (default options) for a model with the A465's physical
/// variant's parameters (its URDF is not the robot the log was made with).
pub fn fit_physical(log: &A465Log) -> perturbid_rs::direct::BaseModel {
    let model = perturbid_rs::robots::a465::model("physical").unwrap();
    let states = perturbid_rs::States::new(6, &log.q, Some(&log.qd), Some(&log.qdd)).unwrap();
    perturbid_rs::direct::identify_base_parameters(
        &model,
        &states,
        &log.tau,
        &perturbid_rs::direct::BaseOptions::default(),
    )
    .unwrap()
}

/// The real Panda log preprocessed with the default options, and the Panda model of
/// example-robot-data; None where either is absent (each says why on stderr).
pub fn panda_preprocessed() -> Option<(perturbid_rs::Model, perturbid_rs::Recording)> {
    let rec = panda_log()?;
    let Some(model) = panda_model() else {
        eprintln!("SKIPPED: the Panda URDF of example-robot-data is not installed");
        return None;
    };
    let options = perturbid_rs::logs::preprocess::PreprocessOptions::default();
    Some((
        model,
        perturbid_rs::logs::preprocess::preprocess(&rec, &options).unwrap(),
    ))
}

/// The A465's plan at Table 2 (default options) and its simulated recordings with 0.05 N m of
/// torque noise and 1e-5 rad of position noise (seed 11).
pub fn a465_noisy_runs() -> (perturbid_rs::local::Plan, Vec<perturbid_rs::Recording>) {
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let plan = perturbid_rs::local::plan_experiments(
        &model,
        &table2(),
        &perturbid_rs::local::PlanOptions::default(),
    )
    .unwrap();
    let mut sim = perturbid_rs::SimulationOptions::new(&model);
    sim.torque_noise = vec![0.05; model.nv];
    sim.position_noise = vec![1e-5; model.nv];
    sim.seed = 11;
    let recs = perturbid_rs::simulate_plan(&model, &plan, &sim).unwrap();
    (plan, recs)
}

/// The largest difference between two local models' D*, H* and G*, in the standard errors of
/// the second (`clean`).
pub fn worst_in_stderr(
    a: &perturbid_rs::local::LocalModel,
    clean: &perturbid_rs::local::LocalModel,
) -> f64 {
    [(&a.d, &clean.d), (&a.h, &clean.h), (&a.g, &clean.g)]
        .into_iter()
        .map(|(x, c)| {
            let c = c.as_ref().unwrap();
            (mat(x) - &c.matrix)
                .zip_map(&c.stderr, |d, s| (d / s).abs())
                .max()
        })
        .fold(0.0, f64::max)
}

/// Inverse dynamics of every sample of row-major `k x n` states (row-major `k x n` torques).
pub fn torques(
    model: &perturbid_rs::Model,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: perturbid_rs::Gravity,
) -> Vec<f64> {
    let n = model.nv;
    let mut data = perturbid_rs::Data::new(model);
    (0..q.len() / n)
        .flat_map(|s| {
            let r = s * n..(s + 1) * n;
            perturbid_rs::rnea(
                model,
                &mut data,
                &q[r.clone()],
                &qd[r.clone()],
                &qdd[r],
                gravity,
            )
            .unwrap();
            data.tau.as_slice().to_vec()
        })
        .collect()
}

/// The A465 running a 5-harmonic excitation for 12 s at about 1 kHz (irregular steps), with
/// viscous and Coulomb friction (steps at every velocity reversal), torque noise of 0.03 N m
/// and positions on a grid of 2^20 counts a revolution.
pub fn a465_noisy_log() -> perturbid_rs::Recording {
    let model = perturbid_rs::robots::a465::model("physical").unwrap();
    let n = 6;
    let mut rng = Rng(5);
    let traj = a465_excitation(&mut rng);
    let mut t = vec![0.0];
    while *t.last().unwrap() < 12.0 {
        let last = *t.last().unwrap();
        t.push(last + rng.uniform(0.0008, 0.0012));
    }
    let s = traj.sample(&t);
    let tau = torques_with_friction(&model, &s, &mut rng, |r| 0.03 * normal(r));
    let count = 2f64.powi(20) / (2.0 * std::f64::consts::PI);
    let q = s.q.iter().map(|x| (x * count).round() / count).collect();
    perturbid_rs::Recording::new("log", n, t, q, tau, None, None).unwrap()
}

/// A standard normal draw (Box-Muller).
pub fn normal(rng: &mut Rng) -> f64 {
    let (u, v) = (rng.uniform(1e-12, 1.0), rng.uniform(0.0, 1.0));
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// The A465's base parameters (its "physical" model) fitted to `rec` preprocessed with
/// `options`, with the preprocessed recording.
pub fn fit_preprocessed(
    rec: &perturbid_rs::Recording,
    options: &perturbid_rs::logs::preprocess::PreprocessOptions,
) -> (perturbid_rs::Recording, perturbid_rs::direct::BaseModel) {
    let p = perturbid_rs::logs::preprocess::preprocess(rec, options).unwrap();
    let states = perturbid_rs::States::new(6, &p.q, p.qd.as_deref(), p.qdd.as_deref()).unwrap();
    let fit = perturbid_rs::direct::identify_base_parameters(
        &perturbid_rs::robots::a465::model("physical").unwrap(),
        &states,
        &p.tau,
        &perturbid_rs::direct::BaseOptions::default(),
    )
    .unwrap();
    (p, fit)
}

/// The largest difference of `a`'s parameters from `b`'s, in `b`'s standard errors.
pub fn moved_in_stderr(
    a: &perturbid_rs::direct::BaseModel,
    b: &perturbid_rs::direct::BaseModel,
) -> f64 {
    a.theta
        .iter()
        .zip(&b.theta)
        .zip(&b.stderr)
        .map(|((x, y), s)| (x - y).abs() / s)
        .fold(0.0, f64::max)
}
