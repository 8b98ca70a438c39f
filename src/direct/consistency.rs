//! Physical consistency of a full parameter vector: every body's mass positive and its
//! pseudo-inertia `J = [[Sigma, h], [h^T, m]]` (`Sigma = tr(I)/2 1 - I` for the rotational
//! inertia `I` about the joint frame's origin, `h` the first mass moment) positive
//! semi-definite, which is exactly what a rigid body with a non-negative mass density can have
//! (Wensing, Kim and Slotine 2017; the triangle inequalities of the principal moments follow);
//! viscous and Coulomb friction coefficients non-negative.

use nalgebra::{Matrix3, Matrix4, Vector3};

use super::parameters::ParameterLayout;
use crate::error::{Error, Result};

/// Relative tolerance on the smallest pseudo-inertia eigenvalue (against the largest).
pub const CONSISTENCY_TOLERANCE: f64 = 1e-9;

/// One body's verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyConsistency {
    /// The parameter names' prefix (the body's link).
    pub link: String,
    pub mass: f64,
    /// Eigenvalues of the pseudo-inertia, ascending (kg m^2, kg m, kg mixed: the matrix's own
    /// units).
    pub eigenvalues: [f64; 4],
    /// The smallest eigenvalue over the largest magnitude: below `-1e-9` is inconsistent.
    pub relative_min: f64,
    /// Why the body is inconsistent, `None` when it is consistent.
    pub problem: Option<String>,
}

/// The verdict on a parameter vector.
#[derive(Clone, Debug, PartialEq)]
pub struct ConsistencyReport {
    pub bodies: Vec<BodyConsistency>,
    /// Friction parameters below zero: (name, value).
    pub negative_friction: Vec<(String, f64)>,
}

impl ConsistencyReport {
    /// True when every body and every friction coefficient is physically possible.
    pub fn is_consistent(&self) -> bool {
        self.negative_friction.is_empty() && self.bodies.iter().all(|b| b.problem.is_none())
    }
}

/// The pseudo-inertia of the 10 parameters `p` (Pinocchio's order).
pub fn pseudo_inertia(p: &[f64]) -> Matrix4<f64> {
    let i = Matrix3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]);
    let sigma = Matrix3::identity() * (0.5 * i.trace()) - i;
    let h = Vector3::new(p[1], p[2], p[3]);
    let mut j = Matrix4::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&sigma);
    j.fixed_view_mut::<3, 1>(0, 3).copy_from(&h);
    j.fixed_view_mut::<1, 3>(3, 0).copy_from(&h.transpose());
    j[(3, 3)] = p[0];
    j
}

/// The 10 parameters of a pseudo-inertia `J = [[Sigma, h], [h^T, m]]` (the inverse of
/// [`pseudo_inertia`] on symmetric matrices): `I = tr(Sigma) 1 - Sigma`.
pub fn parameters_of_pseudo_inertia(j: &Matrix4<f64>) -> [f64; 10] {
    let (sxx, syy, szz) = (j[(0, 0)], j[(1, 1)], j[(2, 2)]);
    [
        j[(3, 3)],
        j[(0, 3)],
        j[(1, 3)],
        j[(2, 3)],
        syy + szz,
        -j[(0, 1)],
        sxx + szz,
        -j[(0, 2)],
        -j[(1, 2)],
        sxx + syy,
    ]
}

/// Checks the full parameter vector `theta` of `layout` (10 per body, then friction): see the
/// module documentation. Errors: `theta` of the wrong length or non-finite.
pub fn check_physical_consistency(
    layout: &ParameterLayout,
    theta: &[f64],
) -> Result<ConsistencyReport> {
    if theta.len() != layout.len() {
        return Err(Error::shape(
            "theta",
            format!("{} parameters (the layout's)", layout.len()),
            theta.len().to_string(),
        ));
    }
    if let Some(i) = theta.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFiniteInput {
            argument: "theta".into(),
            index: i,
            value: theta[i],
        });
    }
    let mut bodies = Vec::with_capacity(layout.nbodies);
    for b in 0..layout.nbodies {
        let p = &theta[10 * b..10 * b + 10];
        let link = layout.names[10 * b]
            .rsplit_once('.')
            .map_or(String::new(), |(l, _)| l.to_string());
        // NaN eigenvalues where the parameters are not finite: judged below as not consistent
        let mut eig: Vec<f64> = crate::decomposition::symmetric_eigen(pseudo_inertia(p))
            .map_or(vec![f64::NAN; 4], |e| {
                e.eigenvalues.iter().copied().collect()
            });
        eig.sort_by(f64::total_cmp);
        let scale = eig.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let relative_min = if scale > 0.0 { eig[0] / scale } else { 0.0 };
        let problem = if p[0] < 0.0 {
            Some(format!("mass {} kg is negative", p[0]))
        } else if relative_min < -CONSISTENCY_TOLERANCE {
            Some(format!(
                "pseudo-inertia not positive semi-definite (smallest eigenvalue {:.3e}, {:.3} of the largest): no rigid body has this mass distribution",
                eig[0], relative_min
            ))
        } else {
            None
        };
        bodies.push(BodyConsistency {
            link,
            mass: p[0],
            eigenvalues: [eig[0], eig[1], eig[2], eig[3]],
            relative_min,
            problem,
        });
    }
    let negative_friction = layout.names[10 * layout.nbodies..]
        .iter()
        .zip(&theta[10 * layout.nbodies..])
        .filter(|(name, v)| !name.ends_with(".offset") && **v < 0.0)
        .map(|(name, v)| (name.clone(), *v))
        .collect();
    Ok(ConsistencyReport {
        bodies,
        negative_friction,
    })
}
