//! A study resolved into cases: robots read (URDF text kept, so that a worker on another
//! machine needs nothing but the study), operating points given or sampled, true robots as
//! documents; case `i` decoded from its index. Everything here serialises (JSON), so a study
//! ships to Dask workers as one string.

use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::config::{SpeedClass, StudyConfig, MAX_CASES};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::local::Design;
use crate::model::Model;
use crate::rehearsal::TrueRobot;

/// A robot of a resolved study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyRobot {
    pub name: String,
    /// The URDF's text, or None for a built-in robot.
    pub urdf: Option<String>,
    pub lock: std::collections::BTreeMap<String, f64>,
    pub points: Vec<StudyPoint>,
}

/// An operating point of a resolved study (rad, rad/s, rad/s^2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyPoint {
    pub name: String,
    /// `given`, or the speed class it was sampled in.
    pub speed_class: String,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

/// A study ready to run: every case is decoded from its index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Study {
    pub config: StudyConfig,
    pub robots: Vec<StudyRobot>,
    pub true_robots: Vec<(String, TrueRobot)>,
    /// The library's version (part of every case's id).
    pub version: String,
}

/// One case: indices into the study's lists and the values of the other dimensions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Case {
    pub index: usize,
    pub robot: usize,
    pub point: usize,
    pub true_robot: usize,
    /// Torque noise replacing the true robot's (N m); None: the document's.
    pub noise: Option<f64>,
    pub design: Design,
    /// K; None: the planner's default.
    pub k: Option<usize>,
    /// Perturbation sizes as multiples of the defaults.
    pub perturbation: f64,
    pub seed: u64,
}

impl Study {
    /// Resolves `config` (from `source`; relative files are relative to `base`).
    pub fn resolve(config: StudyConfig, base: &Path, source: &str) -> Result<Study> {
        config.check(source)?;
        let mut robots = Vec::new();
        for (r, spec) in config.robots.iter().enumerate() {
            let is_file = spec.name.ends_with(".urdf") || spec.name.contains('/');
            let urdf = if is_file {
                Some(crate::io::read_document(base.join(&spec.name))?)
            } else {
                None
            };
            let mut robot = StudyRobot {
                name: spec.name.clone(),
                urdf,
                lock: spec.lock.clone(),
                points: vec![],
            };
            let model = robot.model()?;
            for p in &config.points {
                if p.q.len() == model.nv && p.qd.len() == model.nv && p.qdd.len() == model.nv {
                    // within this robot's limits: a case at it could not be planned
                    crate::operating_point::OperatingPoint::new(
                        p.q.clone(),
                        p.qd.clone(),
                        p.qdd.clone(),
                    )
                    .and_then(|op| op.check(&model))
                    .map_err(|e| Error::Config {
                        location: format!("{source}, points '{}'", p.name),
                        message: e.to_string(),
                    })?;
                    robot.points.push(StudyPoint {
                        name: p.name.clone(),
                        speed_class: "given".into(),
                        q: p.q.clone(),
                        qd: p.qd.clone(),
                        qdd: p.qdd.clone(),
                    });
                }
            }
            if let Some(s) = &config.sample_points {
                let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
                rng.set_stream(r as u64);
                for class in &s.speed_classes {
                    for i in 0..s.count {
                        robot.points.push(sample_point(&model, *class, i, &mut rng));
                    }
                }
            }
            if robot.points.is_empty() {
                return Err(Error::Config {
                    location: format!("{source}, points"),
                    message: format!(
                        "no operating point for robot '{}' ({} joints): the given points have other lengths",
                        spec.name, model.nv
                    ),
                });
            }
            robots.push(robot);
        }
        let mut true_robots = Vec::new();
        if config.true_robots.is_empty() {
            true_robots.push(("ideal".to_string(), ideal()));
        }
        for t in &config.true_robots {
            let at = format!("{source}, true_robots '{}'", t.name);
            let doc: serde_json::Value = match (&t.file, &t.document) {
                (Some(f), None) => {
                    let path = base.join(f);
                    let text = crate::io::read_document(&path)?;
                    // checked as a document first, so that its errors name the file
                    TrueRobot::from_json_in(&text, &path.display().to_string())?;
                    serde_json::from_str(&text).expect("parsed above")
                }
                (None, Some(v)) => {
                    let mut v = v.clone();
                    if let Some(o) = v.as_object_mut() {
                        o.entry("format").or_insert(TrueRobot::tag().into());
                    }
                    v
                }
                _ => serde_json::to_value(ideal()).expect("serialisable"),
            };
            for (name, value) in sweep(&t.name, &doc, &t.sweep, &at)? {
                let robot = TrueRobot::from_json_in(
                    &value.to_string(),
                    &format!("{source}, true_robots '{name}'"),
                )?;
                for r in &robots {
                    robot.check(&r.model()?).map_err(|e| Error::Config {
                        location: format!("{source}, true_robots '{name}'"),
                        message: format!("for robot '{}': {e}", r.name),
                    })?;
                }
                true_robots.push((name, robot));
            }
        }
        let study = Study {
            config,
            robots,
            true_robots,
            version: env!("CARGO_PKG_VERSION").to_string(),
        };
        let n = study.len_checked()?;
        if n > MAX_CASES {
            return Err(Error::Config {
                location: source.into(),
                message: format!("{n} cases, at most {MAX_CASES} allowed"),
            });
        }
        Ok(study)
    }

    /// Reads the TOML file `path` and resolves it.
    pub fn from_file(path: &Path) -> Result<Study> {
        let (config, _) = crate::io::config::read_toml::<StudyConfig>(path)?;
        let base = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        Study::resolve(config, base, &path.display().to_string())
    }

    /// Cases per point of a robot.
    fn per_point(&self) -> usize {
        let c = &self.config;
        self.true_robots.len()
            * c.noise.len().max(1)
            * c.local.designs.len()
            * c.local.k.len()
            * c.local.perturbation.len()
            * c.seeds as usize
    }

    fn len_checked(&self) -> Result<usize> {
        let points: usize = self.robots.iter().map(|r| r.points.len()).sum();
        points
            .checked_mul(self.per_point())
            .ok_or_else(|| Error::Config {
                location: self.config.name.clone(),
                message: "the number of cases overflows".into(),
            })
    }

    /// The number of cases.
    pub fn len(&self) -> usize {
        self.len_checked().unwrap_or(usize::MAX)
    }

    /// Whether the study has no case (never, once resolved).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Case `index` (0-based): robots, then points, true robots, noise levels, designs, K,
    /// perturbation sizes, and seeds fastest.
    pub fn case(&self, index: usize) -> Result<Case> {
        let per_point = self.per_point();
        let mut rest = index;
        let mut robot = None;
        for (r, rb) in self.robots.iter().enumerate() {
            let here = rb.points.len() * per_point;
            if rest < here {
                robot = Some(r);
                break;
            }
            rest -= here;
        }
        let Some(robot) = robot else {
            return Err(Error::invalid(
                "case",
                format!("{index}; the study has {} cases", self.len()),
            ));
        };
        let c = &self.config;
        let mut take = |size: usize| {
            let v = rest % size;
            rest /= size;
            v
        };
        let seed = take(c.seeds as usize) as u64;
        let perturbation = c.local.perturbation[take(c.local.perturbation.len())];
        let k = c.local.k[take(c.local.k.len())];
        let design = c.local.designs[take(c.local.designs.len())];
        let noise = if c.noise.is_empty() {
            None
        } else {
            Some(c.noise[take(c.noise.len())])
        };
        let true_robot = take(self.true_robots.len());
        let point = rest;
        Ok(Case {
            index,
            robot,
            point,
            true_robot,
            noise,
            design,
            k: (k > 0).then_some(k),
            perturbation,
            seed,
        })
    }

    /// A case's id: a hash of everything that decides its result (the robot, the point, the
    /// true robot, the method settings, the seed, the library's version), so that a rerun of
    /// a changed study recomputes exactly the cases that changed.
    pub fn case_id(&self, case: &Case) -> String {
        let c = &self.config;
        let key = serde_json::json!({
            "robot": &self.robots[case.robot].name,
            "urdf": &self.robots[case.robot].urdf,
            "lock": &self.robots[case.robot].lock,
            "point": &self.robots[case.robot].points[case.point],
            "true_robot": &self.true_robots[case.true_robot],
            "noise": case.noise,
            "design": case.design.name(),
            "k": case.k,
            "perturbation": case.perturbation,
            "seed": case.seed,
            "direct": &c.direct,
            "evaluation": &c.evaluation,
            "methods": &c.methods,
            "version": &self.version,
        });
        format!("{:016x}", fnv1a(key.to_string().as_bytes()))
    }
}

impl StudyRobot {
    /// The robot's model, joints locked.
    pub fn model(&self) -> Result<Model> {
        let options = crate::urdf::LoadOptions {
            lock: self.lock.clone(),
            ..crate::urdf::LoadOptions::default()
        };
        match &self.urdf {
            Some(text) => crate::urdf::model_from_urdf_str(text, &self.name, &options),
            None => crate::robots::builtin_with(&self.name, &options),
        }
    }
}

/// The ideal true robot: the model itself, gravity excluded as in the paper, no friction, no
/// noise.
fn ideal() -> TrueRobot {
    TrueRobot {
        gravity: crate::gravity::Gravity::Excluded,
        ..TrueRobot::default()
    }
}

/// A point within the limits: q in the middle 80 % of each range (within +-pi for a
/// continuous joint), |qd| the class's fraction of the speed limit with a random sign, qdd
/// within +-30 % of the acceleration limit (1 rad/s and 2 rad/s^2 where a limit is infinite).
fn sample_point(model: &Model, class: SpeedClass, i: usize, rng: &mut ChaCha8Rng) -> StudyPoint {
    let n = model.nv;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let vel = model.velocity_limit();
    let acc = model.acceleration_limit();
    for (j, l) in model.limits.iter().enumerate() {
        let (lo, hi) = if (l.upper - l.lower).is_finite() {
            (l.lower, l.upper)
        } else {
            (-std::f64::consts::PI, std::f64::consts::PI)
        };
        q[j] = lo + (hi - lo) * rng.random_range(0.1..0.9);
        let v = if vel[j].is_finite() { vel[j] } else { 1.0 };
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        qd[j] = sign * class.fraction() * v;
        let a = if acc[j].is_finite() { acc[j] } else { 2.0 };
        qdd[j] = a * rng.random_range(-0.3..0.3);
    }
    StudyPoint {
        name: format!("{}{}", class.name(), i + 1),
        speed_class: class.name().to_string(),
        q,
        qd,
        qdd,
    }
}

/// 64-bit FNV-1a: a stable hash (the same on every machine and run).
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// At most this many true robots from one sweep.
const MAX_SWEEP: usize = 1000;

/// The documents of a sweep: `doc` with every combination of the values of `keys` set, each
/// named `name[key=value,...]`; `doc` itself, named `name`, without keys.
fn sweep(
    name: &str,
    doc: &serde_json::Value,
    keys: &std::collections::BTreeMap<String, Vec<serde_json::Value>>,
    at: &str,
) -> Result<Vec<(String, serde_json::Value)>> {
    let bad = |message: String| Error::Config {
        location: format!("{at}, sweep"),
        message,
    };
    let mut out = vec![(Vec::<String>::new(), doc.clone())];
    for (key, values) in keys {
        if values.is_empty() {
            return Err(bad(format!("'{key}' has no values")));
        }
        if out.len().saturating_mul(values.len()) > MAX_SWEEP {
            return Err(bad(format!("more than {MAX_SWEEP} combinations")));
        }
        let mut next = Vec::new();
        for (labels, d) in &out {
            for v in values {
                let mut d = d.clone();
                set_path(&mut d, key, v.clone()).map_err(|m| bad(format!("'{key}': {m}")))?;
                let mut labels = labels.clone();
                labels.push(format!("{key}={v}"));
                next.push((labels, d));
            }
        }
        out = next;
    }
    Ok(out
        .into_iter()
        .map(|(labels, d)| {
            let n = if labels.is_empty() {
                name.to_string()
            } else {
                format!("{name}[{}]", labels.join(","))
            };
            (n, d)
        })
        .collect())
}

/// Sets the value at the dotted `path` of `doc` (objects are created where a field is
/// missing; list entries must exist).
fn set_path(
    doc: &mut serde_json::Value,
    path: &str,
    value: serde_json::Value,
) -> std::result::Result<(), String> {
    let mut here = doc;
    let parts: Vec<&str> = path.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        if here.is_null() {
            // an absent section (`payload: null`) is created by the path
            *here = serde_json::Value::Object(Default::default());
        }
        here = match here {
            serde_json::Value::Object(o) => {
                if last {
                    o.insert(part.to_string(), value);
                    return Ok(());
                }
                o.entry(part.to_string())
                    .or_insert_with(|| serde_json::Value::Object(Default::default()))
            }
            serde_json::Value::Array(a) => {
                let k: usize = part
                    .parse()
                    .map_err(|_| format!("'{part}' is not a list index"))?;
                let len = a.len();
                let slot = a
                    .get_mut(k)
                    .ok_or_else(|| format!("index {k} beyond the list's {len} entries"))?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                return Err(format!(
                    "'{part}' is inside a value that is neither a table nor a list"
                ))
            }
        };
    }
    Err("an empty path".into())
}
