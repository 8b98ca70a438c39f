//! The regressor of a batch of samples for the parameter vector of the direct method (its
//! layout, [`ParameterLayout`], is the robot model's: [`crate::parameters`]).

use crate::algorithms::regressor::{joint_torque_regressor, PARAMS_PER_BODY};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;
use nalgebra::DMatrix;

pub use crate::parameters::{sign0, FrictionTerms, ParameterLayout};

/// The identification regressor of a batch: `(k nv) x layout.len()`, row `s * nv + j` the torque
/// of joint `j` at sample `s` per unit of each parameter. `gravity` includes gravity.
pub fn regressor_matrix(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
) -> Result<DMatrix<f64>> {
    let nv = model.nv;
    let k = states.len();
    let mut out = DMatrix::zeros(k * nv, layout.len());
    fill_regressor(model, layout, states, gravity, 0..k, &mut out, 0)?;
    Ok(out)
}

/// Samples in one block of [`regressor_blocks`] (a 7-joint arm's 1024 samples of 100 parameters
/// are 5.7 MB).
const REGRESSOR_BLOCK: usize = 1024;

/// The regressor of `states` a block of samples at a time, never all of it at once: calls
/// `f(range, phi)` for consecutive ranges of samples, in order, `phi` their regressor
/// (`range.len() nv x layout.len()`, rows as in [`regressor_matrix`]). Stops at Ctrl-C.
pub fn regressor_blocks(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
    mut f: impl FnMut(std::ops::Range<usize>, &DMatrix<f64>) -> Result<()>,
) -> Result<()> {
    let (k, nv) = (states.len(), model.nv);
    let mut phi = DMatrix::zeros(0, layout.len());
    for start in (0..k).step_by(REGRESSOR_BLOCK) {
        crate::interrupt::check("the regressor")?;
        let range = start..(start + REGRESSOR_BLOCK).min(k);
        if phi.nrows() != range.len() * nv {
            phi = DMatrix::zeros(range.len() * nv, layout.len());
        }
        fill_regressor(model, layout, states, gravity, range.clone(), &mut phi, 0)?;
        f(range, &phi)?;
    }
    Ok(())
}

/// Writes the regressor rows of samples `range` into `out` from row `row0` on.
pub(crate) fn fill_regressor(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
    range: std::ops::Range<usize>,
    out: &mut DMatrix<f64>,
    row0: usize,
) -> Result<()> {
    let nv = model.nv;
    let ni = PARAMS_PER_BODY * model.nbodies();
    let terms = layout.friction.names();
    let mut data = Data::new(model);
    let mut y = std::mem::take(&mut data.regressor);
    let zeros = vec![0.0; nv];
    for (r, s) in range.enumerate() {
        let x = states.sample(s);
        let (q, qd, qdd) = (x.q, x.qd.unwrap_or(&zeros), x.qdd.unwrap_or(&zeros));
        joint_torque_regressor(model, &mut data, q, qd, qdd, gravity, &mut y)
            .map_err(|e| states.at(s, e))?;
        let base = row0 + r * nv;
        out.view_mut((base, 0), (nv, ni)).copy_from(&y);
        for j in 0..nv {
            for (t, name) in terms.iter().enumerate() {
                out[(base + j, ni + j * terms.len() + t)] = match *name {
                    "viscous" => qd[j],
                    "coulomb" => states.coulomb_at(s, j),
                    "armature" => qdd[j],
                    _ => 1.0,
                };
            }
        }
    }
    Ok(())
}
