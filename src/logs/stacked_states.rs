//! The samples of several runs one after the other, owned: what a fit over several logs reads
//! (`identify-direct LOG LOG ...`, [`crate::direct::drive_gains`]).

use crate::error::{Error, Result};
pub use crate::logs::repeated_samples::run_name;
use crate::states::States;

/// States with velocities and accelerations, row-major `k x nv`, and per sample `nv` values of
/// data (torques, or a logged signal), of several runs stacked in their order. A Coulomb column
/// where any run has one ([`States::with_coulomb`]): `sign(qd)` for the samples of those
/// without.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StackedStates {
    pub nv: usize,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub coulomb: Option<Vec<f64>>,
    pub data: Vec<f64>,
    /// The samples of each run, in their order: a fit's [`crate::direct::BaseOptions::runs`],
    /// so that each run's residuals are read as a time series of their own.
    pub runs: Vec<usize>,
}

impl StackedStates {
    /// `parts` (each a run's states, with velocities and accelerations, and its data, `nv`
    /// values a sample) one after the other. Errors: no part, parts of other joints than the
    /// first's, a part without velocities or accelerations (naming it, from 0), data of
    /// another shape, two parts that share samples (positions and data alike, bit for bit,
    /// over [`crate::logs::repeated_samples::RUN`] samples or more: a run given twice).
    pub fn of(parts: &[(States<'_>, &[f64])]) -> Result<Self> {
        Self::of_named(parts, &[], "runs")
    }

    /// [`Self::of`] with the parts named in its errors by `names` (`run r` where none is given)
    /// and those errors' argument `argument`.
    pub fn of_named(
        parts: &[(States<'_>, &[f64])],
        names: &[String],
        argument: &str,
    ) -> Result<Self> {
        let Some((first, _)) = parts.first() else {
            return Err(Error::invalid(argument, "no run to stack"));
        };
        let name = |r: usize| run_name(names, r);
        let nv = first.nv();
        let k: usize = parts.iter().map(|(s, _)| s.len()).sum();
        let filtered = parts.iter().any(|(s, _)| s.coulomb().is_some());
        let mut out = Self {
            nv,
            q: Vec::with_capacity(k * nv),
            qd: Vec::with_capacity(k * nv),
            qdd: Vec::with_capacity(k * nv),
            coulomb: filtered.then(|| Vec::with_capacity(k * nv)),
            data: Vec::with_capacity(k * nv),
            runs: parts.iter().map(|(s, _)| s.len()).collect(),
        };
        for (r, (s, data)) in parts.iter().enumerate() {
            let (Some(qd), Some(qdd)) = (s.qd(), s.qdd()) else {
                return Err(Error::invalid(
                    argument,
                    format!(
                        "{} has no velocities and accelerations: preprocess its log first",
                        name(r)
                    ),
                ));
            };
            if s.nv() != nv {
                return Err(Error::invalid(
                    argument,
                    format!("{} has {} joints, {} {nv}", name(r), s.nv(), name(0)),
                ));
            }
            s.check_companion("data", data, nv)?;
            out.q.extend_from_slice(s.q());
            out.qd.extend_from_slice(qd);
            out.qdd.extend_from_slice(qdd);
            if let Some(c) = &mut out.coulomb {
                c.extend((0..s.len() * nv).map(|x| s.coulomb_at(x / nv, x % nv)));
            }
            out.data.extend_from_slice(data);
        }
        let prints = (parts.iter())
            .map(|(s, data)| crate::logs::repeated_samples::SamplePrints::of(nv, &[s.q(), data]))
            .collect::<Result<Vec<_>>>()?;
        let names: Vec<String> = (0..parts.len()).map(name).collect();
        crate::logs::repeated_samples::refuse_shared_samples(&prints, &names, argument, "samples")?;
        Ok(out)
    }

    /// The stacked states (their Coulomb column where there is one).
    pub fn states(&self) -> Result<States<'_>> {
        let states = States::new(self.nv, &self.q, Some(&self.qd), Some(&self.qdd))?;
        match &self.coulomb {
            Some(c) => states.with_coulomb(c),
            None => Ok(states),
        }
    }
}
