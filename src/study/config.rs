//! The study's configuration (a TOML file, `perturbid study STUDY.toml`, or the same as a
//! Python dict): what varies and over which values. See docs/study.md.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::choice::choice;
use crate::error::{Error, Result};
use crate::local::Design;

/// A study: the product of every list below is the set of cases; each case runs every method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyConfig {
    /// A name for the report.
    pub name: String,
    /// Seeds `0..seeds`: each seeds the local plan's random design, the true robot's random
    /// effects and noise, and the direct method's excitation design.
    #[serde(default = "default_seeds")]
    pub seeds: u64,
    /// Robots: built-in names or URDF files (relative to the study file), with locks.
    pub robots: Vec<RobotSpec>,
    /// Operating points given by hand (for robots with that many joints).
    #[serde(default)]
    pub points: Vec<PointSpec>,
    /// Operating points sampled within each robot's limits, per speed class.
    #[serde(default)]
    pub sample_points: Option<SampleSpec>,
    /// The true robots the methods are rehearsed on (default: one ideal robot, gravity
    /// excluded as in the paper, no friction, no noise).
    #[serde(default)]
    pub true_robots: Vec<TrueRobotSpec>,
    /// Torque noise levels (N m, standard deviation, every joint) replacing the true robots'
    /// own; empty: the documents' noise.
    #[serde(default)]
    pub noise: Vec<f64>,
    #[serde(default)]
    pub local: LocalSpec,
    #[serde(default)]
    pub direct: DirectSpec,
    #[serde(default)]
    pub evaluation: EvaluationSpec,
    /// The methods compared (default: all).
    #[serde(default = "all_methods")]
    pub methods: Vec<Method>,
}

fn default_seeds() -> u64 {
    1
}

/// A robot of the study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// A built-in name (`a465`, `a465:physical`) or a URDF file.
    pub name: String,
    /// Joints held still: `{ joint = value }` (rad or m).
    #[serde(default)]
    pub lock: BTreeMap<String, f64>,
}

/// An operating point given by hand.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    pub name: String,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

/// Points sampled within the limits: `count` per speed class, seeded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleSpec {
    pub count: usize,
    #[serde(default = "default_classes")]
    pub speed_classes: Vec<SpeedClass>,
    #[serde(default)]
    pub seed: u64,
}

fn default_classes() -> Vec<SpeedClass> {
    vec![SpeedClass::Slow, SpeedClass::Fast]
}

choice! {
    /// How fast the sampled points move: each joint's speed is this fraction of its limit
    /// (random sign), against velocity perturbations of 5 % of the limit by default. `slow`
    /// (2 %): the perturbations reverse the joints, friction changes sign between passes;
    /// `fast` (50 %): no reversal.
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum SpeedClass ("speed class") {
        Slow = "slow",
        Fast = "fast",
    }
}

impl SpeedClass {
    /// |qd_j| as a fraction of joint j's speed limit.
    pub fn fraction(self) -> f64 {
        match self {
            SpeedClass::Slow => 0.02,
            SpeedClass::Fast => 0.5,
        }
    }
}

/// A true robot of the study: a `perturbid-true-robot/1` document (docs/rehearsal.md), from a
/// file (relative to the study file) or written inline as a table; neither: the ideal robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrueRobotSpec {
    pub name: String,
    #[serde(default)]
    pub file: Option<String>,
    #[serde(default)]
    pub document: Option<serde_json::Value>,
    /// Values to sweep: `{ "payload.mass" = [0.5, 1.0, 2.0] }` makes one true robot per value
    /// (per combination when several keys are given), named `NAME[payload.mass=0.5]`; a key
    /// is a path into the document (fields by name, list entries by number:
    /// `friction.coulomb.0`).
    #[serde(default)]
    pub sweep: std::collections::BTreeMap<String, Vec<serde_json::Value>>,
}

/// The local method's experiments.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocalSpec {
    /// Perturbation designs (default: orthogonal).
    #[serde(default = "default_designs")]
    pub designs: Vec<Design>,
    /// Perturbations per experiment K (default: the planner's, 2N); 0 means the default.
    #[serde(default = "default_k")]
    pub k: Vec<usize>,
    /// Perturbation sizes as multiples of the default ones (1 % of the position range, 5 %
    /// of the speed and acceleration limits).
    #[serde(default = "default_scale")]
    pub perturbation: Vec<f64>,
}

fn default_designs() -> Vec<Design> {
    vec![Design::Orthogonal]
}
fn default_k() -> Vec<usize> {
    vec![0]
}
fn default_scale() -> Vec<f64> {
    vec![1.0]
}

impl Default for LocalSpec {
    fn default() -> Self {
        Self {
            designs: default_designs(),
            k: default_k(),
            perturbation: default_scale(),
        }
    }
}

/// The direct method's excitation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectSpec {
    #[serde(default = "default_harmonics")]
    pub harmonics: usize,
    #[serde(default = "default_frequency")]
    pub base_frequency: f64,
    #[serde(default = "default_evaluations")]
    pub max_evaluations: usize,
    /// Periods of the excitation the robot runs; absent: as much robot time as the local
    /// method's separated experiments took (equal robot time).
    #[serde(default)]
    pub periods: Option<f64>,
    /// Sampling rate of the excitation's log (Hz).
    #[serde(default = "default_rate")]
    pub rate: f64,
}

/// The paper's excitation: 10 harmonics of 0.05 Hz (fewer than (3N + 1) / 2 harmonics leave
/// the globally linearised regression rank-deficient: its 3N + 1 columns are then sums of
/// fewer sinusoids).
fn default_harmonics() -> usize {
    10
}
fn default_frequency() -> f64 {
    0.05
}
fn default_evaluations() -> usize {
    300
}
fn default_rate() -> f64 {
    200.0
}

impl Default for DirectSpec {
    fn default() -> Self {
        Self {
            harmonics: default_harmonics(),
            base_frequency: default_frequency(),
            max_evaluations: default_evaluations(),
            periods: None,
            rate: default_rate(),
        }
    }
}

/// Where the models are evaluated: states at distances from P, in multiples of the
/// perturbation size (each of q, qd, qdd moved by `distance` times its size along a random
/// direction).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvaluationSpec {
    #[serde(default = "default_distances")]
    pub distances: Vec<f64>,
    #[serde(default = "default_samples")]
    pub samples: usize,
}

fn default_distances() -> Vec<f64> {
    vec![0.5, 1.0, 2.0, 4.0]
}
fn default_samples() -> usize {
    32
}

impl Default for EvaluationSpec {
    fn default() -> Self {
        Self {
            distances: default_distances(),
            samples: default_samples(),
        }
    }
}

choice! {
    /// An identification method of the study.
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum Method ("method") {
        /// The paper's separated regressions.
        LocalSeparated = "local_separated",
        /// One regression of all experiments for [D H G].
        LocalCombined = "local_combined",
        /// Separated, with the H experiment planned and regressed friction-aware.
        LocalFrictionAware = "local_friction_aware",
        /// Base parameters (viscous, Coulomb, offset friction) by ordinary least squares.
        DirectOls = "direct_ols",
        /// The same by weighted least squares.
        DirectWls = "direct_wls",
        /// Swevers' way: the excitation's log averaged over its whole periods (the measured
        /// positions' harmonics and their derivatives, the torques' band, no filter), the
        /// base parameters weighted by the noise the periods measured (by the residuals where
        /// they measured none, as on a robot without noise). Fails alone where the log holds
        /// fewer than 2 whole periods.
        DirectAveraged = "direct_averaged",
        /// The direct method's globally linearised model about P.
        GlobalLinear = "global_linear",
    }
}

fn all_methods() -> Vec<Method> {
    Method::ALL.to_vec()
}

/// Bounds on what a study may ask for (each named in its error).
pub const MAX_CASES: usize = 1_000_000;
pub const MAX_SAMPLES: usize = 10_000;
pub const MAX_DISTANCES: usize = 100;
pub const MAX_SEEDS: u64 = 1_000_000;
/// Sampled points per speed class, and perturbations per experiment.
pub const MAX_POINTS: usize = 10_000;
pub const MAX_K: usize = 10_000;
/// Perturbation sizes and evaluation distances, as multiples of the default perturbations.
pub const MAX_MULTIPLE: f64 = 100.0;

impl StudyConfig {
    /// Checks what serde cannot: non-empty lists, positive finite numbers, bounds.
    pub fn check(&self, source: &str) -> Result<()> {
        self.check_sizes(source)?;
        self.check_listed_once(source)?;
        self.check_multiples(source)?;
        self.check_names(source)
    }

    /// Lists that are not empty, counts and numbers within their bounds.
    fn check_sizes(&self, source: &str) -> Result<()> {
        let bad = |key: &str, message: String| Error::Config {
            location: format!("{source}, {key}"),
            message,
        };
        if self.robots.is_empty() {
            return Err(bad("robots", "no robot: add a [[robots]] table".into()));
        }
        if self.points.is_empty() && self.sample_points.as_ref().is_none_or(|s| s.count == 0) {
            return Err(bad(
                "points",
                "no operating point: give [[points]] or sample_points = { count = ... }".into(),
            ));
        }
        if let Some(s) = &self.sample_points {
            if s.count > 0 && s.speed_classes.is_empty() {
                return Err(bad(
                    "sample_points.speed_classes",
                    "an empty list: no point would be sampled; give slow, fast or both".into(),
                ));
            }
            if s.count > MAX_POINTS {
                return Err(bad(
                    "sample_points.count",
                    format!("{}; at most {MAX_POINTS}", s.count),
                ));
            }
        }
        if let Some(k) = self.local.k.iter().find(|k| **k > MAX_K) {
            return Err(bad("local.k", format!("{k}; at most {MAX_K}")));
        }
        if self.seeds == 0 || self.seeds > MAX_SEEDS {
            return Err(bad(
                "seeds",
                format!("{}; expected 1..={MAX_SEEDS}", self.seeds),
            ));
        }
        let positive = |key: &str, v: &[f64]| -> Result<()> {
            if v.is_empty() {
                return Err(bad(key, "an empty list".into()));
            }
            match v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                Some(x) => Err(bad(key, format!("{x}; expected positive finite numbers"))),
                None => Ok(()),
            }
        };
        positive("local.perturbation", &self.local.perturbation)?;
        positive("evaluation.distances", &self.evaluation.distances)?;
        positive("direct.base_frequency", &[self.direct.base_frequency])?;
        positive("direct.rate", &[self.direct.rate])?;
        if let Some(p) = self.direct.periods {
            positive("direct.periods", &[p])?;
        }
        if let Some(x) = self.noise.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(bad(
                "noise",
                format!("{x}; expected finite levels >= 0 (N m)"),
            ));
        }
        if self.evaluation.distances.len() > MAX_DISTANCES {
            return Err(bad(
                "evaluation.distances",
                format!("more than {MAX_DISTANCES}"),
            ));
        }
        if !(1..=MAX_SAMPLES).contains(&self.evaluation.samples) {
            return Err(bad(
                "evaluation.samples",
                format!("{}; expected 1..={MAX_SAMPLES}", self.evaluation.samples),
            ));
        }
        if self.local.designs.is_empty() || self.local.k.is_empty() || self.methods.is_empty() {
            return Err(bad("local/methods", "an empty list".into()));
        }
        if self.direct.harmonics == 0 || self.direct.harmonics > 50 {
            return Err(bad(
                "direct.harmonics",
                format!("{}; expected 1..=50", self.direct.harmonics),
            ));
        }
        if self.direct.max_evaluations == 0 || self.direct.max_evaluations > 100_000 {
            return Err(bad(
                "direct.max_evaluations",
                format!("{}; expected 1..=100000", self.direct.max_evaluations),
            ));
        }
        Ok(())
    }

    /// No value listed twice: it would run the same cases twice and count them twice.
    fn check_listed_once(&self, source: &str) -> Result<()> {
        let bad = |key: &str, message: String| Error::Config {
            location: format!("{source}, {key}"),
            message,
        };
        fn twice<T: PartialEq>(v: &[T]) -> Option<&T> {
            v.iter()
                .enumerate()
                .find(|(i, x)| v[..*i].contains(x))
                .map(|(_, x)| x)
        }
        let lists: [(&str, Option<String>); 8] = [
            (
                "local.designs",
                twice(&self.local.designs).map(|x| x.to_string()),
            ),
            ("local.k", twice(&self.local.k).map(|x| x.to_string())),
            (
                "local.perturbation",
                twice(&self.local.perturbation).map(|x| x.to_string()),
            ),
            (
                "evaluation.distances",
                twice(&self.evaluation.distances).map(|x| x.to_string()),
            ),
            ("methods", twice(&self.methods).map(|x| x.to_string())),
            ("noise", twice(&self.noise).map(|x| x.to_string())),
            (
                "sample_points.speed_classes",
                self.sample_points
                    .as_ref()
                    .and_then(|s| twice(&s.speed_classes))
                    .map(|x| x.to_string()),
            ),
            ("robots", twice(&self.robots).map(|r| r.name.clone())),
        ];
        for (key, value) in lists {
            if let Some(value) = value {
                return Err(bad(key, format!("'{value}' is listed twice")));
            }
        }
        Ok(())
    }

    /// Perturbations and distances as multiples of the defaults: past 100 the states leave
    /// any robot's range.
    fn check_multiples(&self, source: &str) -> Result<()> {
        let bad = |key: &str, message: String| Error::Config {
            location: format!("{source}, {key}"),
            message,
        };
        for (key, v) in [
            ("local.perturbation", &self.local.perturbation),
            ("evaluation.distances", &self.evaluation.distances),
        ] {
            if let Some(x) = v.iter().find(|x| **x > MAX_MULTIPLE) {
                return Err(bad(
                    key,
                    format!(
                        "{}; expected at most {MAX_MULTIPLE} (multiples of the default perturbation sizes)",
                        crate::error::shown(*x)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The names label the report's rows, tables and figure: something to read, on one line,
    /// each true robot and point named once.
    fn check_names(&self, source: &str) -> Result<()> {
        let bad = |key: &str, message: String| Error::Config {
            location: format!("{source}, {key}"),
            message,
        };
        let named = std::iter::once(("name", &self.name))
            .chain(self.true_robots.iter().map(|t| ("true_robots", &t.name)))
            .chain(self.points.iter().map(|p| ("points", &p.name)));
        for (key, name) in named {
            if name.trim().is_empty() || name.chars().any(char::is_control) {
                return Err(bad(
                    key,
                    format!("name {name:?}: expected a name to show in the report, on one line"),
                ));
            }
        }
        let mut names = std::collections::BTreeSet::new();
        for t in &self.true_robots {
            if !names.insert(&t.name) {
                return Err(bad("true_robots", format!("'{}' is named twice", t.name)));
            }
            if t.file.is_some() && t.document.is_some() {
                return Err(bad(
                    "true_robots",
                    format!("'{}': give a file or a document, not both", t.name),
                ));
            }
        }
        let mut names = std::collections::BTreeSet::new();
        for p in &self.points {
            if !names.insert(&p.name) {
                return Err(bad("points", format!("'{}' is named twice", p.name)));
            }
        }
        Ok(())
    }
}
