//! The true local model of a rehearsal: what a local identification at an operating point
//! should find on a true robot, from its noise-free torques ([`super::true_torques`]) by
//! central differences. With friction, ripple and cogging the torque is not a rigid-body
//! one, so the truth is the true robot's own expansion, not the URDF's.

use nalgebra::DMatrix;

use super::true_robot::TrueRobot;
use crate::error::Result;
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::states::States;

/// `T*`, `D*`, `H*`, `G*` of the true robot at an operating point (N m and per unit of qdd,
/// qd, q).
#[derive(Clone, Debug, PartialEq)]
pub struct TrueLocal {
    pub torque: Vec<f64>,
    pub d: DMatrix<f64>,
    pub h: DMatrix<f64>,
    pub g: DMatrix<f64>,
}

/// The expansion of `robot`'s noise-free torque about `op` (the nominal model's encoder
/// coordinates): T* its torque there, the matrices its central differences with steps 1e-5
/// rad, 1e-4 rad/s and 1e-3 rad/s^2 (second-order accurate; friction is smooth away from zero
/// speed, so a joint within a step of zero speed has no derivative there).
pub fn true_local(nominal: &Model, robot: &TrueRobot, op: &OperatingPoint) -> Result<TrueLocal> {
    let n = nominal.nv;
    op.check(nominal)?;
    let torque_at = |state: &[Vec<f64>; 3]| -> Result<Vec<f64>> {
        let states = States::new(n, &state[0], Some(&state[1]), Some(&state[2]))?;
        super::recorded::true_torques(nominal, robot, &states)
    };
    let base = [op.q.clone(), op.qd.clone(), op.qdd.clone()];
    let torque = torque_at(&base)?;
    let mut matrices = [
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
    ];
    for (var, step) in [(0, 1e-5), (1, 1e-4), (2, 1e-3)] {
        for j in 0..n {
            let (mut up, mut down) = (base.clone(), base.clone());
            up[var][j] += step;
            down[var][j] -= step;
            let (a, b) = (torque_at(&up)?, torque_at(&down)?);
            for i in 0..n {
                matrices[var][(i, j)] = (a[i] - b[i]) / (2.0 * step);
            }
        }
    }
    let [g, h, d] = matrices;
    Ok(TrueLocal { torque, d, h, g })
}
