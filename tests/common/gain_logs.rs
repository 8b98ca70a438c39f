//! Logs of motor currents for the drive-gain tests (tests/drive_gains.rs,
//! tests/drive_gains_instrumental.rs): the A465 along seeded excitations, alone or with a
//! known payload, its torques with friction over made-up gains, plus white noise.

use super::{a465_excitation, normal, torques_with_friction, Rng};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::direct::{
    identify_drive_gains_with, regressor_matrix, BaseOptions, BaseParameters, DriveGainFit,
    GainEstimator, GainRun, Weighting,
};
use perturbid_rs::rehearsal::{Payload, TrueRobot};
use perturbid_rs::trajectory::Samples;
use perturbid_rs::{Gravity, Model, States};

/// N m per ampere of the A465's six drives (made up: a torque constant times a gear ratio).
pub const GAINS: [f64; 6] = [42.0, 65.0, 38.0, 9.0, 7.5, 4.0];

pub fn payload() -> Payload {
    Payload {
        link: "link6".into(),
        mass: 2.0,
        com: [0.02, -0.01, 0.08],
        inertia: [0.004, 0.0, 0.0, 0.004, 0.0, 0.002],
    }
}

/// 8 s at 500 Hz of the seeded excitation.
pub fn motion(seed: u64) -> Samples {
    let traj = a465_excitation(&mut Rng(seed));
    let t: Vec<f64> = (0..4000).map(|i| i as f64 * 2e-3).collect();
    traj.sample(&t)
}

/// `truth` with `payload` fixed on (itself where None).
pub fn carrying(truth: &Model, payload: Option<&Payload>) -> Model {
    match payload {
        Some(p) => TrueRobot {
            payload: Some(p.clone()),
            ..TrueRobot::default()
        }
        .rigid_body_model(truth)
        .unwrap(),
        None => truth.clone(),
    }
}

/// The logged currents of `truth` (with the payload when given) along `s`: torques with
/// friction over the gains, plus `noise` A of white noise.
pub fn currents(
    truth: &Model,
    s: &Samples,
    loaded: Option<&Payload>,
    noise: f64,
    seed: u64,
) -> Vec<f64> {
    let robot = carrying(truth, loaded);
    let mut rng = Rng(seed);
    let tau = torques_with_friction(&robot, s, &mut rng, |_| 0.0);
    (tau.iter().enumerate())
        .map(|(i, t)| t / GAINS[i % 6] + noise * normal(&mut rng))
        .collect()
}

/// A run of the robot alone along `x[0]` and one with `payload` along `x[1]`, their signals
/// `i`.
pub fn alone_then_loaded<'a>(
    x: [&'a Samples; 2],
    i: [&'a [f64]; 2],
    payload: &'a Payload,
) -> [GainRun<'a>; 2] {
    [
        GainRun {
            states: states(x[0]),
            signal: i[0],
            payload: None,
        },
        GainRun {
            states: states(x[1]),
            signal: i[1],
            payload: Some(payload),
        },
    ]
}

/// Two runs' logs: the robot alone along motion 3, and along motion 4 with the payload (or
/// alone too, where `loaded` is false), their currents under `noise` A.
pub struct Logs {
    pub truth: Model,
    pub a: Samples,
    pub b: Samples,
    pub ia: Vec<f64>,
    pub ib: Vec<f64>,
    pub p: Payload,
}

pub fn logs(noise: f64, loaded: bool) -> Logs {
    let (truth, p) = (truth(), payload());
    let (a, b) = (motion(3), motion(4));
    let ia = currents(&truth, &a, None, noise, 1);
    let ib = currents(&truth, &b, loaded.then_some(&p), noise, 2);
    Logs {
        truth,
        a,
        b,
        ia,
        ib,
        p,
    }
}

/// The logs the dense comparisons use: motions 6 and 7 (the second loaded), 1e-3 A of noise.
pub fn dense_logs() -> Logs {
    let (truth, p) = (truth(), payload());
    let (a, b) = (motion(6), motion(7));
    let ia = currents(&truth, &a, None, 1e-3, 3);
    let ib = currents(&truth, &b, Some(&p), 1e-3, 4);
    Logs {
        truth,
        a,
        b,
        ia,
        ib,
        p,
    }
}

impl Logs {
    /// The runs as identified: the second given as carrying the payload.
    pub fn runs(&self) -> [GainRun<'_>; 2] {
        alone_then_loaded([&self.a, &self.b], [&self.ia, &self.ib], &self.p)
    }

    /// The runs identified by OLS (so that the dense system is the one the streaming fit
    /// reduces) with `estimator`, and the system built whole ([`dense_system`]) over the
    /// fit's base parameters.
    pub fn ols_and_dense(
        &self,
        estimator: GainEstimator,
    ) -> (DriveGainFit, DMatrix<f64>, DVector<f64>) {
        let options = BaseOptions {
            weighting: Weighting::Ols,
            ..BaseOptions::default()
        };
        let fit =
            identify_drive_gains_with(&self.truth, &self.runs(), &options, estimator).unwrap();
        let (x, y) = dense_system(
            &self.truth,
            &fit.model.base,
            &self.p,
            [(&self.a, &self.ia, false), (&self.b, &self.ib, true)],
        );
        (fit, x, y)
    }
}

pub fn truth() -> Model {
    perturbid_rs::robots::a465::model("kinsheel2010").unwrap()
}

pub fn states(s: &Samples) -> States<'_> {
    States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap()
}

/// The drive-gain system built whole over `runs` (each its motion, its currents and whether it
/// carried `payload`): `[Phi_base | -diag(i)] [theta; K] = -tau_L`, the regressor `x` (one row
/// a sample and joint, the joints' signal columns after the base columns) and `-tau_L`.
pub fn dense_system(
    truth: &Model,
    base: &BaseParameters,
    payload: &Payload,
    runs: [(&Samples, &[f64], bool); 2],
) -> (DMatrix<f64>, DVector<f64>) {
    let loaded = carrying(truth, Some(payload));
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for (s, i, with) in runs {
        let phi = base
            .select(&regressor_matrix(truth, &base.layout, &states(s), Gravity::Included).unwrap());
        let payload_tau = if with {
            let (l, r) = (
                super::torques(&loaded, &s.q, &s.qd, &s.qdd, Gravity::Included),
                super::torques(truth, &s.q, &s.qd, &s.qdd, Gravity::Included),
            );
            l.iter().zip(&r).map(|(l, r)| l - r).collect()
        } else {
            vec![0.0; s.q.len()]
        };
        for r in 0..phi.nrows() {
            let mut row: Vec<f64> = phi.row(r).iter().copied().collect();
            row.extend((0..6).map(|j| if j == r % 6 { -i[r] } else { 0.0 }));
            rows.push(row);
            rhs.push(-payload_tau[r]);
        }
    }
    let cols = rows[0].len();
    (
        DMatrix::from_fn(rows.len(), cols, |r, c| rows[r][c]),
        DVector::from_vec(rhs),
    )
}

/// The least-squares solution of `x theta = y` by nalgebra's SVD, the columns scaled to unit
/// norm (as the fit does, for the SVD's tolerance).
pub fn dense_least_squares(x: &DMatrix<f64>, y: &DVector<f64>) -> Vec<f64> {
    let cols = x.ncols();
    let scale: Vec<f64> = (0..cols).map(|c| x.column(c).norm()).collect();
    let xs = DMatrix::from_fn(x.nrows(), cols, |r, c| x[(r, c)] / scale[c]);
    let sol = xs.svd(true, true).solve(y, 1e-14).unwrap();
    (0..cols).map(|c| sol[c] / scale[c]).collect()
}
