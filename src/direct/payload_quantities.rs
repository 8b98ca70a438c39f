//! A payload's quantities (mass, centre of mass, inertia about it) and its ten inertial
//! parameters (Pinocchio's order: `m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz`, about a
//! body's joint frame), each from the other, with the Jacobian the delta rule needs, and in
//! another frame (a link behind fixed joints).

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::model::payload::Payload;
use crate::spatial::Se3;

/// The payload's quantities `[m, cx, cy, cz, ixx, ixy, ixz, iyy, iyz, izz]` (inertia about the
/// centre of mass) of its ten parameters `pi` (Pinocchio's order, about the joint frame), and
/// their Jacobian (`10 x 10`, row per quantity). `pi[0]` must not be 0.
pub fn payload_of_parameters(pi: &[f64; 10]) -> ([f64; 10], DMatrix<f64>) {
    let m = pi[0];
    let h = [pi[1], pi[2], pi[3]];
    // Io as (a, b) -> index into pi
    let io = |a: usize, b: usize| -> usize {
        match (a.min(b), a.max(b)) {
            (0, 0) => 4,
            (0, 1) => 5,
            (1, 1) => 6,
            (0, 2) => 7,
            (1, 2) => 8,
            _ => 9,
        }
    };
    let entries = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
    let hh: f64 = h.iter().map(|v| v * v).sum();
    let delta = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
    let mut out = [0.0; 10];
    let mut jac = DMatrix::zeros(10, 10);
    out[0] = m;
    jac[(0, 0)] = 1.0;
    for i in 0..3 {
        out[1 + i] = h[i] / m;
        jac[(1 + i, 0)] = -h[i] / (m * m);
        jac[(1 + i, 1 + i)] = 1.0 / m;
    }
    // Ic = Io - (|h|^2 / m) 1 + h h^T / m
    for (e, &(a, b)) in entries.iter().enumerate() {
        let row = 4 + e;
        out[row] = pi[io(a, b)] - hh / m * delta(a, b) + h[a] * h[b] / m;
        jac[(row, io(a, b))] = 1.0;
        jac[(row, 0)] = hh / (m * m) * delta(a, b) - h[a] * h[b] / (m * m);
        for k in 0..3 {
            jac[(row, 1 + k)] =
                -2.0 * h[k] / m * delta(a, b) + (delta(a, k) * h[b] + h[a] * delta(b, k)) / m;
        }
    }
    (out, jac)
}

/// The payload's quantities `u` (`[m, c, I_c]` as [`payload_of_parameters`] gives them) and
/// their covariance `cu` (`10 x 10`), given in a body's frame, in the frame of a link at
/// `pose` in it: `c' = R^T (c - p)`, `I_c' = R^T I_c R` (the covariance by the same linear map).
pub fn in_link_frame(u: &[f64; 10], cu: &DMatrix<f64>, pose: &Se3) -> ([f64; 10], DMatrix<f64>) {
    let rt = pose.rotation.transpose();
    let entries = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
    let sym = |v: &[f64]| Matrix3::new(v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5]);
    // the linear map of the quantities: 1, R^T on the centre, R^T . R on the inertia's entries
    let mut a = DMatrix::zeros(10, 10);
    a[(0, 0)] = 1.0;
    for i in 0..3 {
        for j in 0..3 {
            a[(1 + i, 1 + j)] = rt[(i, j)];
        }
    }
    for (e, _) in entries.iter().enumerate() {
        let mut basis = [0.0; 6];
        basis[e] = 1.0;
        let image = rt * sym(&basis) * pose.rotation;
        for (f, &(r, c)) in entries.iter().enumerate() {
            a[(4 + f, 4 + e)] = image[(r, c)];
        }
    }
    let c = rt * (Vector3::new(u[1], u[2], u[3]) - pose.translation);
    let i = rt * sym(&u[4..]) * pose.rotation;
    let mut out = [0.0; 10];
    out[0] = u[0];
    out[1..4].copy_from_slice(c.as_slice());
    for (f, &(r, col)) in entries.iter().enumerate() {
        out[4 + f] = i[(r, col)];
    }
    (out, &a * cu * a.transpose())
}

/// The ten parameters `pi` (Pinocchio's order, about its link's frame) of `payload`.
pub fn parameters_of_payload(payload: &Payload) -> [f64; 10] {
    crate::algorithms::regressor::dynamic_parameters(&payload.spatial_inertia())
}
