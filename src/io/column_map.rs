//! Logs written by other tools, read as recordings: their columns renamed to `t`, `q1..qN`,
//! `qd1..qN`, `qdd1..qN`, `tau1..tauN`, scaled to SI units, and the columns a recording has no
//! place for left out by name (docs/logs.md).
//!
//! A map is given as `TARGET=SOURCE[*SCALE]` entries and `IGNORE` patterns:
//! - `TARGET` is `t`, or one of `q`, `qd`, `qdd`, `tau` for every joint (then `SOURCE` holds
//!   `{i}` for the joint's index from 0, `{j}` for its number from 1 or `{joint}` for its name:
//!   `q=actual_q_{i}`), or one joint's (`q3=enc_c`);
//! - `SCALE` is a number (`-1` for a signal that counts the other way) or a unit the values are
//!   in: `deg` (degrees, read as radians), `ms`, `us`, `ns` (read as seconds);
//! - an `IGNORE` pattern names a column the recording leaves out, or ends in `*` for every
//!   column that starts with what precedes it (`actual_TCP_*`). A column a `TARGET` names is
//!   read even where a pattern matches it.
//!
//! Every entry must find its columns in a log, a target may come from one column only, and a
//! column may give one target only; the log's columns a map leaves alone keep their names (and
//! a recording refuses those it has no place for, as without a map).

use std::collections::HashMap;

use super::table::{Kept, Selection, Table};
use crate::error::{Error, Result};

/// Entries and patterns at most in one map (more is no log's).
pub const MAX_ENTRIES: usize = 10_000;

/// The variables a recording holds per joint.
const PER_JOINT: [&str; 4] = ["q", "qd", "qdd", "tau"];

/// One `TARGET=SOURCE[*SCALE]` entry.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    /// `t`, or a per-joint variable ([`PER_JOINT`]).
    var: String,
    /// For one joint only: its index from 0.
    joint: Option<usize>,
    source: String,
    scale: f64,
    /// The entry as given, for messages.
    given: String,
}

/// How a log's columns are read as a recording's (see the module documentation). The default
/// map reads every column under its own name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ColumnMap {
    entries: Vec<Entry>,
    ignore: Vec<String>,
}

fn invalid(message: String) -> Error {
    Error::InvalidArgument {
        argument: "--column".into(),
        message,
    }
}

/// The factor of a `SCALE`: a finite number other than 0, or a unit's.
fn scale_of(text: &str, given: &str) -> Result<f64> {
    let unit = match text {
        "deg" => Some(std::f64::consts::PI / 180.0),
        "ms" => Some(1e-3),
        "us" => Some(1e-6),
        "ns" => Some(1e-9),
        _ => None,
    };
    match unit.or_else(|| text.parse::<f64>().ok()) {
        Some(s) if s.is_finite() && s != 0.0 && s.abs() <= 1e12 && s.abs() >= 1e-12 => Ok(s),
        _ => Err(invalid(format!(
            "'{given}': the scale '{text}' is no factor: expected a number from 1e-12 to 1e12 in size (not 0), or deg, ms, us, ns"
        ))),
    }
}

impl ColumnMap {
    /// The map of `entries` (`TARGET=SOURCE[*SCALE]`) and `ignore` patterns (each a column's
    /// name or a prefix ending in `*`; a pattern may list several, separated by commas).
    /// Errors name the entry and what was expected: a target that is not `t`, a variable or a
    /// variable with a joint number from 1, a per-joint template without `{i}`, `{j}` or
    /// `{joint}`, a scale that is no factor (a time's must be positive), a target given twice.
    pub fn new(entries: &[String], ignore: &[String]) -> Result<Self> {
        if entries.len() + ignore.len() > MAX_ENTRIES {
            return Err(invalid(format!(
                "{} entries and patterns, expected at most {MAX_ENTRIES}",
                entries.len() + ignore.len()
            )));
        }
        let mut map = Self::default();
        for given in entries {
            let (target, rest) = given.split_once('=').ok_or_else(|| {
                invalid(format!(
                    "'{given}': expected TARGET=SOURCE, e.g. q=actual_q_{{i}}, t=timestamp*ms or tau3=effort_c"
                ))
            })?;
            let target = target.trim();
            let (source, scale) = match rest.rsplit_once('*') {
                Some((source, scale)) if !scale.is_empty() => {
                    (source.trim(), scale_of(scale.trim(), given)?)
                }
                _ => (rest.trim(), 1.0),
            };
            if source.is_empty() {
                return Err(invalid(format!("'{given}': no source column after '='")));
            }
            let (var, joint) = match target {
                "t" => ("t", None),
                v if PER_JOINT.contains(&v) => (v, None),
                v => {
                    let digits = v.trim_start_matches(|c: char| c.is_ascii_alphabetic());
                    let var = &v[..v.len() - digits.len()];
                    match (PER_JOINT.contains(&var), digits.parse::<usize>()) {
                        (true, Ok(j)) if j >= 1 => (var, Some(j - 1)),
                        _ => {
                            return Err(invalid(format!(
                                "'{given}': the target '{target}' is none of t, q, qd, qdd, tau (every joint) or q1, qd1, qdd1, tau1, ... (one joint, numbered from 1)"
                            )))
                        }
                    }
                }
            };
            let template = ["{i}", "{j}", "{joint}"].iter().any(|p| source.contains(p));
            if var != "t" && joint.is_none() && !template {
                return Err(invalid(format!(
                    "'{given}': a source for every joint must say where the joint goes: {{i}} (its index from 0), {{j}} (its number from 1) or {{joint}} (its name), e.g. {var}=actual_{var}_{{i}}"
                )));
            }
            if (var == "t" || joint.is_some()) && template {
                return Err(invalid(format!(
                    "'{given}': '{target}' is one column, its source a column's name, not a template"
                )));
            }
            if var == "t" && scale < 0.0 {
                return Err(invalid(format!(
                    "'{given}': a time's scale must be positive (time must increase)"
                )));
            }
            // a per-joint template gives every joint's: no other entry of its variable
            if let Some(other) = (map.entries.iter()).find(|e| {
                e.var == var && (e.joint == joint || e.joint.is_none() || joint.is_none())
            }) {
                let j = joint
                    .or(other.joint)
                    .map_or(String::new(), |j| (j + 1).to_string());
                return Err(invalid(format!(
                    "'{}' and '{given}' both give {var}{j}",
                    other.given
                )));
            }
            map.entries.push(Entry {
                var: var.into(),
                joint,
                source: source.into(),
                scale,
                given: given.clone(),
            });
        }
        for pattern in ignore.iter().flat_map(|p| p.split(',')) {
            let pattern = pattern.trim();
            if pattern.is_empty() || pattern == "*" {
                return Err(Error::invalid(
                    "--ignore-columns",
                    format!(
                        "'{pattern}': expected a column's name, or the start of names followed by '*' (leaving out every column is no recording)"
                    ),
                ));
            }
            map.ignore.push(pattern.into());
        }
        Ok(map)
    }

    /// Whether the map reads every column under its own name.
    pub fn is_identity(&self) -> bool {
        self.entries.is_empty() && self.ignore.is_empty()
    }

    /// The columns of a log with the header `columns` to read for the joints `joints` (see
    /// the module documentation), and those left out; errors (a [`Error::Recording`] of
    /// `source`) name the entry whose column is missing or taken, listing the log's columns.
    pub fn select(
        &self,
        source: &str,
        columns: &[String],
        joints: &[String],
    ) -> Result<(Selection, Vec<String>)> {
        let bad = |message: String| Error::Recording {
            recording: source.into(),
            message,
        };
        let listed = || super::table::listed(columns, 40);
        // by name: a header of a hundred thousand columns is read in linear time
        let index: HashMap<&str, usize> = (columns.iter().enumerate())
            .map(|(c, name)| (name.as_str(), c))
            .collect();
        // the target each mapped column is read as, and the column of each target
        let mut mapped: Vec<Option<(String, f64, &str)>> = vec![None; columns.len()];
        let mut source_of: HashMap<String, usize> = HashMap::new();
        for e in &self.entries {
            let targets: Vec<(String, String)> = match (e.var.as_str(), e.joint) {
                ("t", _) => vec![("t".into(), e.source.clone())],
                (var, Some(j)) => vec![(format!("{var}{}", j + 1), e.source.clone())],
                (var, None) => (joints.iter().enumerate())
                    .map(|(i, name)| {
                        let from = (e.source.replace("{i}", &i.to_string()))
                            .replace("{j}", &(i + 1).to_string())
                            .replace("{joint}", name);
                        (format!("{var}{}", i + 1), from)
                    })
                    .collect(),
            };
            for (target, from) in targets {
                let c = *index.get(from.as_str()).ok_or_else(|| {
                    bad(format!(
                        "--column '{}': no column '{from}' for {target}; the columns are: {}",
                        e.given,
                        listed()
                    ))
                })?;
                if let Some((other, _, given)) = &mapped[c] {
                    return Err(bad(format!(
                        "--column '{}': column '{from}' is already read as {other} (by '{given}'); a column gives one target",
                        e.given
                    )));
                }
                source_of.insert(target.clone(), c);
                mapped[c] = Some((target, e.scale, &e.given));
            }
        }
        let ignored = |name: &str| {
            self.ignore.iter().any(|p| match p.strip_suffix('*') {
                Some(prefix) => name.starts_with(prefix),
                None => name == p,
            })
        };
        let mut keep = Vec::with_capacity(columns.len());
        let mut left_out = Vec::new();
        for (c, name) in columns.iter().enumerate() {
            match &mapped[c] {
                Some((target, scale, _)) => keep.push(Kept {
                    source: c,
                    name: target.clone(),
                    scale: *scale,
                }),
                None if ignored(name) => left_out.push(name.clone()),
                // a column the log names as a target a map entry also gives
                None => match source_of.get(name) {
                    Some(&m) => {
                        let given = mapped[m].as_ref().map_or("", |m| m.2);
                        return Err(bad(format!(
                            "column '{name}' and column '{}' (by --column '{given}') are both read as {name}: leave one out (--ignore-columns {name})",
                            columns[m]
                        )));
                    }
                    None => keep.push(Kept {
                        source: c,
                        name: name.clone(),
                        scale: 1.0,
                    }),
                },
            }
        }
        Ok((Selection { keep }, left_out))
    }

    /// The table in the CSV file at `path`, its columns selected for the joints `joints`
    /// ([`Self::select`]), and the names of those left out.
    pub fn read(&self, path: &std::path::Path, joints: &[String]) -> Result<(Table, Vec<String>)> {
        let (table, read) = self.read_explained(path, joints)?;
        Ok((table, read.left_out))
    }

    /// [`Self::read`], with how each column was read ([`ReadColumns`]).
    pub fn read_explained(
        &self,
        path: &std::path::Path,
        joints: &[String],
    ) -> Result<(Table, ReadColumns)> {
        let source = path.display().to_string();
        let text = super::read_text(path)?;
        let mut read = ReadColumns::default();
        let table = Table::parse_selected(&source, &text, |columns| {
            let (selection, left_out) = self.select(&source, columns, joints)?;
            read = ReadColumns {
                header: columns.to_vec(),
                selection: selection.clone(),
                left_out,
            };
            Ok(selection)
        })?;
        Ok((table, read))
    }
}

/// How a log's columns were read ([`ColumnMap::read_explained`]): its header, the columns
/// kept (the name each is read as and its scale) and those left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadColumns {
    pub header: Vec<String>,
    pub selection: Selection,
    pub left_out: Vec<String>,
}

/// What a map left out of the log `path`, as a line for a command's output (None where
/// nothing was).
pub fn left_out_note(path: &std::path::Path, left_out: &[String]) -> Option<String> {
    if left_out.is_empty() {
        return None;
    }
    Some(format!(
        "{}: {} column(s) left out (--ignore-columns): {}",
        path.display(),
        left_out.len(),
        super::table::listed(left_out, 12)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints() -> Vec<String> {
        vec!["shoulder".into(), "elbow".into()]
    }

    fn map(entries: &[&str], ignore: &[&str]) -> Result<ColumnMap> {
        let own = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        ColumnMap::new(&own(entries), &own(ignore))
    }

    #[test]
    fn a_foreign_log_is_read_renamed_scaled_and_with_its_extras_left_out() {
        let text =
            "timestamp,actual_q_0,actual_q_1,pos_elbow,m_shoulder,m_elbow,state,actual_TCP_x\n\
                    1000,0.5,1,10,2,3,RUNNING,0.1\n\
                    1002,0.6,2,20,4,5,RUNNING,0.2\n";
        let m = map(
            &[
                "t=timestamp*ms",
                "q=actual_q_{i}",
                "tau={joint}*-1",
                "tau1=m_shoulder",
                "tau2=m_elbow*2",
            ],
            &[],
        );
        // tau given for every joint and for each: refused as given twice
        assert!(m.unwrap_err().to_string().contains("both give tau1"));
        let m = map(
            &[
                "t=timestamp*ms",
                "q=actual_q_{i}",
                "tau1=m_shoulder",
                "tau2=m_elbow*-2",
            ],
            &["state", "actual_TCP_*", "pos_elbow"],
        )
        .unwrap();
        let mut left = vec![];
        let t = Table::parse_selected("log.csv", text, |c| {
            let (s, out) = m.select("log.csv", c, &joints())?;
            left = out;
            Ok(s)
        })
        .unwrap();
        assert_eq!(t.columns, ["t", "q1", "q2", "tau1", "tau2"]);
        assert_eq!(
            t.values,
            [1.0, 0.5, 1.0, 2.0, -6.0, 1.002, 0.6, 2.0, 4.0, -10.0]
        );
        assert_eq!(left, ["pos_elbow", "state", "actual_TCP_x"]);
        let rec = crate::logs::read_recording(&t, &joints()).unwrap();
        assert_eq!(rec.q, [0.5, 1.0, 0.6, 2.0]);
        // {j}, {joint} and degrees
        let m = map(&["q=pos_{joint}*deg", "qd=v{j}"], &[]).unwrap();
        let (s, _) = m
            .select(
                "x",
                &[
                    "pos_shoulder".into(),
                    "pos_elbow".into(),
                    "v1".into(),
                    "v2".into(),
                ],
                &joints(),
            )
            .unwrap();
        let names: Vec<&str> = s.keep.iter().map(|k| k.name.as_str()).collect();
        assert_eq!(names, ["q1", "q2", "qd1", "qd2"]);
        assert!((s.keep[0].scale - std::f64::consts::PI / 180.0).abs() < 1e-18);
    }

    #[test]
    fn a_map_that_does_not_fit_its_log_is_refused_naming_the_entry() {
        let cols: Vec<String> = ["t", "q1", "q2", "a0", "a1", "tau1", "tau2"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let cases: [(&[&str], &[&str], &str); 6] = [
            (
                &["q=b{i}"],
                &[],
                "--column 'q=b{i}': no column 'b0' for q1; the columns are: t, q1",
            ),
            (
                &["q=a{i}"],
                &[],
                "column 'q1' and column 'a0' (by --column 'q=a{i}') are both read as q1",
            ),
            (&["q=a{i}"], &["q1", "q2"], ""),
            (
                &["q1=a0", "qd1=a0"],
                &["q1"],
                "column 'a0' is already read as q1",
            ),
            (&["tau1=a1"], &[], "are both read as tau1"),
            (&[], &["a*"], ""),
        ];
        for (entries, ignore, expected) in cases {
            let got = map(entries, ignore)
                .unwrap()
                .select("log.csv", &cols, &joints());
            match (expected, got) {
                ("", Ok(_)) => {}
                (e, Err(err)) if !e.is_empty() => {
                    let s = err.to_string();
                    assert!(s.starts_with("log.csv: ") && s.contains(e), "{s}");
                }
                (e, other) => panic!("{entries:?} {ignore:?}: expected '{e}', got {other:?}"),
            }
        }
        for (entries, ignore, expected) in [
            (&["q"][..], &[][..], "expected TARGET=SOURCE"),
            (&["x=a"], &[], "the target 'x' is none of"),
            (&["q0=a"], &[], "the target 'q0' is none of"),
            (&["q=actual"], &[], "must say where the joint goes"),
            (
                &["t=time{i}"],
                &[],
                "one column, its source a column's name",
            ),
            (&["t=time*-1"], &[], "a time's scale must be positive"),
            (&["q=a{i}*0"], &[], "the scale '0' is no factor"),
            (&["q=a{i}*inch"], &[], "the scale 'inch' is no factor"),
            (&["q=a{i}*1e300"], &[], "is no factor"),
            (&["q="], &[], "no source column"),
            (&[], &["*"], "leaving out every column"),
            (&[], &["a,,b"], "expected a column's name"),
        ] {
            let e = map(entries, ignore).unwrap_err().to_string();
            assert!(e.contains(expected), "{entries:?} {ignore:?}: {e}");
        }
    }

    #[test]
    fn values_are_checked_after_scaling_and_named_by_the_file_s_column() {
        let m = map(&["t=stamp*ns", "q1=enc"], &["note"]).unwrap();
        let select = |c: &[String]| m.select("log.csv", c, &["j".to_string()]).map(|s| s.0);
        let e = Table::parse_selected(
            "log.csv",
            "stamp,enc,tau1,note\n1,2,3,x\n2,abc,3,y\n",
            select,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("line 3, column 'enc' (read as q1): 'abc' is not a number"),
            "{e}"
        );
        let m = map(&["q1=enc*1e12"], &[]).unwrap();
        let select = |c: &[String]| m.select("log.csv", c, &["j".to_string()]).map(|s| s.0);
        let e = Table::parse_selected("log.csv", "t,enc,tau1\n0,1e300,3\n", select)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(
                "line 2, column 'enc' (read as q1): 1e300 times 1e12 is beyond the largest number"
            ),
            "{e}"
        );
        // the time checked as scaled, under its target's name
        let m = map(&["t=stamp*ns"], &[]).unwrap();
        let select = |c: &[String]| m.select("log.csv", c, &["j".to_string()]).map(|s| s.0);
        let e = Table::parse_selected("log.csv", "stamp,q1,tau1\n5,1,1\n5,1,1\n", select)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 3, column 't': time does not increase"),
            "{e}"
        );
    }
}
