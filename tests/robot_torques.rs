//! A robot's own torques as a model (`RobotTorques`): its expansion is the derivative of its
//! predictions (finite differences), its D the mass matrix, and its friction the URDF's.

mod common;

use common::Rng;
use perturbid_rs::{mass_matrix, robots, Data, OperatingPoint, RobotTorques, States, TorqueModel};

fn with_friction() -> perturbid_rs::Model {
    let mut robot = robots::a465::model("kinsheel2010").unwrap();
    for (j, l) in robot.limits.iter_mut().enumerate() {
        l.damping = 0.3 + 0.1 * j as f64;
        l.friction = 0.5 + 0.2 * j as f64;
    }
    robot
}

fn predict_one(m: &RobotTorques<'_>, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let n = q.len();
    m.predict(&States::new(n, q, Some(qd), Some(qdd)).unwrap())
        .unwrap()
}

#[test]
fn the_expansion_is_the_derivative_of_the_predictions() {
    let robot = with_friction();
    let model = RobotTorques::new(&robot);
    let mut rng = Rng(9);
    let n = robot.nv;
    for _ in 0..5 {
        let q = rng.vector(n, 1.0);
        // velocities away from 0, where the Coulomb term steps
        let qd: Vec<f64> = rng
            .vector(n, 1.0)
            .iter()
            .map(|v| v + 0.5 * v.signum())
            .collect();
        let qdd = rng.vector(n, 2.0);
        let op = OperatingPoint::new(q.clone(), qd.clone(), qdd.clone()).unwrap();
        let e = model.linearize(&op).unwrap();
        let at = predict_one(&model, &q, &qd, &qdd);
        for (t, a) in e.torque.iter().zip(&at) {
            assert!((t - a).abs() < 1e-12 * a.abs().max(1.0));
        }
        let h = 1e-6;
        for c in 0..n {
            let step = |x: &[f64], s: f64| {
                let mut y = x.to_vec();
                y[c] += s;
                y
            };
            let central = |f: &dyn Fn(f64) -> Vec<f64>| -> Vec<f64> {
                let (a, b) = (f(h), f(-h));
                a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect()
            };
            let dq = central(&|s| predict_one(&model, &step(&q, s), &qd, &qdd));
            let dv = central(&|s| predict_one(&model, &q, &step(&qd, s), &qdd));
            let da = central(&|s| predict_one(&model, &q, &qd, &step(&qdd, s)));
            let rest =
                central(&|s| predict_one(&model, &step(&q, s), &vec![0.0; n], &vec![0.0; n]));
            for r in 0..n {
                for (name, m, fd) in [
                    ("G", &e.g, &dq),
                    ("H", &e.h, &dv),
                    ("D", &e.d, &da),
                    ("G_static", e.g_static.as_ref().unwrap(), &rest),
                ] {
                    assert!(
                        (m[(r, c)] - fd[r]).abs() < 1e-5 * (1.0 + fd[r].abs()),
                        "{name}[{r},{c}] {} vs {}",
                        m[(r, c)],
                        fd[r]
                    );
                }
            }
        }
        // D is the mass matrix, with the armature
        let mut data = Data::new(&robot);
        mass_matrix(&robot, &mut data, &q).unwrap();
        assert!((&e.d - &data.m).norm() < 1e-12 * data.m.norm());
    }
}

#[test]
fn friction_is_the_urdfs_and_a_filtered_logs_coulomb_column_is_used() {
    let robot = with_friction();
    let bare = robots::a465::model("kinsheel2010").unwrap();
    let (m, b) = (RobotTorques::new(&robot), RobotTorques::new(&bare));
    assert!(m.has_friction() && !b.has_friction());
    let n = robot.nv;
    let mut rng = Rng(2);
    let (q, qd, qdd) = (
        rng.vector(3 * n, 1.0),
        rng.vector(3 * n, 1.0),
        rng.vector(3 * n, 1.0),
    );
    let coulomb: Vec<f64> = qd.iter().map(|v| 0.5 * v.signum()).collect();
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let filtered = States::new(n, &q, Some(&qd), Some(&qdd))
        .unwrap()
        .with_coulomb(&coulomb)
        .unwrap();
    let (with, without, half) = (
        m.predict(&states).unwrap(),
        b.predict(&states).unwrap(),
        m.predict(&filtered).unwrap(),
    );
    for i in 0..3 * n {
        let l = &robot.limits[i % n];
        let f = l.damping * qd[i] + l.friction * qd[i].signum();
        assert!((with[i] - without[i] - f).abs() < 1e-12 * (1.0 + with[i].abs()));
        let g = l.damping * qd[i] + l.friction * coulomb[i];
        assert!((half[i] - without[i] - g).abs() < 1e-12 * (1.0 + half[i].abs()));
    }
    // at rest: no Coulomb torque; without velocities: none of either
    let zeros = vec![0.0; n];
    let rest = States::new(n, &q[..n], Some(&zeros), Some(&qdd[..n])).unwrap();
    let only_q = States::new(n, &q[..n], None, Some(&qdd[..n])).unwrap();
    assert_eq!(m.predict(&rest).unwrap(), b.predict(&rest).unwrap());
    assert_eq!(m.predict(&only_q).unwrap(), b.predict(&only_q).unwrap());
}
