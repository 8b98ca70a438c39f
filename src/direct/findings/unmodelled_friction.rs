//! Joint terms the model leaves out that its residuals hold. (the checks that find them: [`crate::direct::unmodelled_friction`]).

use serde::{Deserialize, Serialize};

use crate::direct::parameters::FrictionTerms;

/// The most samples the fit with the missing terms takes (spread evenly over the data).
pub const SAMPLES: usize = 20_000;

/// The fraction of a joint's residual sum of squares the missing terms must take off.
pub const EXPLAINED: f64 = 0.25;

/// How many standard errors from 0 a joint's own new term must be to be named.
pub const T_NAMED: f64 = 5.0;

/// The friction terms a joint can have.
pub(in crate::direct) const TERMS: [&str; 3] = ["viscous", "coulomb", "offset"];

/// A friction term of one joint, identified by the fit with the missing terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissingTerm {
    /// `viscous`, `coulomb` or `offset`.
    pub term: String,
    /// Its coefficient (N m s/rad, N m, N m; N s/m, N, N for a prismatic joint).
    pub coefficient: f64,
    /// Its standard error (same unit), inflated for residuals correlated from sample to sample.
    pub stderr: f64,
}

/// A joint whose residual the friction terms the fit lacks take [`EXPLAINED`] or more off,
/// with a term of its own [`T_NAMED`] standard errors from 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnmodelledFriction {
    pub joint: String,
    /// The fraction of its residual sum of squares the terms take off.
    pub explained: f64,
    /// Its residual RMS without and with the terms (N m or N), over the samples refitted.
    pub residual_rms: f64,
    pub remaining_rms: f64,
    /// Its new terms that are [`T_NAMED`] standard errors from 0.
    pub terms: Vec<MissingTerm>,
}

impl UnmodelledFriction {
    /// What is wrong with the entry of a saved model, if anything: an unknown joint or term,
    /// no term, a fraction outside [0, 1], values that are not finite.
    pub fn problem(&self, joints: &[String]) -> Option<String> {
        let who = format!("joint '{}'", self.joint);
        if !joints.contains(&self.joint) {
            return Some(format!("{who} is not one of the model's"));
        }
        if !(0.0..=1.0).contains(&self.explained) {
            return Some(format!(
                "{who}: explained {}, expected a fraction in [0, 1]",
                self.explained
            ));
        }
        let values = [self.residual_rms, self.remaining_rms];
        let terms = self.terms.iter().flat_map(|t| [t.coefficient, t.stderr]);
        if values.into_iter().chain(terms).any(|v| !v.is_finite()) {
            return Some(format!("{who}: a value that is not finite"));
        }
        if self.terms.is_empty() {
            return Some(format!("{who}: no term, expected at least one"));
        }
        (self
            .terms
            .iter()
            .find(|t| !TERMS.contains(&t.term.as_str())))
        .map(|t| {
            format!(
                "{who}: term '{}', expected one of {}",
                t.term,
                TERMS.join(", ")
            )
        })
    }

    /// The joint's terms as `coulomb 0.43 +- 0.01 N m` items.
    fn terms_said(&self) -> String {
        let unit = |t: &str| if t == "viscous" { " N m s/rad" } else { " N m" };
        (self.terms.iter())
            .map(|t| {
                let (c, se, u) = (t.coefficient, t.stderr, unit(&t.term));
                format!("{} {c:.3} +- {se:.3}{u}", t.term)
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The warning for `found` (none if empty) in a fit with the terms `fitted`: which joints,
/// which terms, and the friction terms to identify with (those fitted and those found).
pub fn finding(found: &[UnmodelledFriction], fitted: FrictionTerms) -> Option<String> {
    if found.is_empty() {
        return None;
    }
    let named = |t: &str| found.iter().any(|f| f.terms.iter().any(|x| x.term == t));
    // the armature is added where the robot has one: not the user's to ask for
    let with = FrictionTerms {
        viscous: fitted.viscous || named("viscous"),
        coulomb: fitted.coulomb || named("coulomb"),
        offset: fitted.offset || named("offset"),
        armature: false,
    };
    let names = with.names();
    let joints: Vec<String> = (found.iter())
        .map(|f| {
            format!(
                "'{}' ({}; residual RMS {:.3}, {:.3} with them: {:.0} % of its sum of squares)",
                f.joint,
                f.terms_said(),
                f.residual_rms,
                f.remaining_rms,
                100.0 * f.explained
            )
        })
        .collect();
    Some(format!(
        "friction the fit leaves out shows in the torques of {} joint(s), and the fit's parameters took up what they could of it: {}; identify with those terms (friction=[{}] in Python, --friction {} on the command line)",
        found.len(),
        joints.join("; "),
        names.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", "),
        names.join(",")
    ))
}
