//! Recordings and trajectories as CSV: columns `t`, `q1..qN`, optional `qd1..qN` and
//! `qdd1..qN`, `tau1..tauN`; or the same named after the joints (`q_<joint>`, `qd_<joint>`,
//! `qdd_<joint>`, `tau_<joint>`).

use crate::error::{shown, Error, Result};
use crate::io::table::{listed, time_hint, Table};
use crate::logs::recording::Recording;
use crate::trajectory::Samples;

/// The column of variable `var` (`q`, `qd`, `qdd`, `tau`) of joint `j`: `var{j+1}` or
/// `var_<name>`.
fn find(table: &Table, var: &str, j: usize, name: &str) -> Option<usize> {
    table
        .index(&format!("{var}{}", j + 1))
        .or_else(|| table.index(&format!("{var}_{name}")))
}

/// Joint columns of a table, found by name, with a record of which columns were used.
struct Columns<'a> {
    table: &'a Table,
    joints: &'a [String],
    used: Vec<bool>,
}

impl<'a> Columns<'a> {
    fn new(table: &'a Table, joints: &'a [String]) -> Result<(Self, Vec<f64>)> {
        if joints.is_empty() {
            return Err(Error::invalid(
                "joints",
                format!("no joint names to read {} with", table.source),
            ));
        }
        if let Some(j) = (1..joints.len()).find(|&j| joints[..j].contains(&joints[j])) {
            return Err(Error::invalid(
                "joints",
                format!(
                    "joint '{}' named twice ([{}]); expected the robot's joint names",
                    joints[j],
                    joints.join(", ")
                ),
            ));
        }
        let t_col = table.index("t").ok_or_else(|| {
            // a header in capitals (T, Q1, TAU1) is not read as the names it spells
            let case = if table.index("T").is_some() {
                " (names are lower case: t, q1, tau1, ...)"
            } else {
                ""
            };
            bad(
                table,
                format!(
                    "no column 't' (time, s){case}; the columns are: {}; a log from another tool: read its time as t with --column t=NAME (*ms, *us or *ns for a time in those units; Python columns=, docs/logs.md)",
                    listed(&table.columns, 40)
                ),
            )
        })?;
        let mut used = vec![false; table.columns.len()];
        used[t_col] = true;
        let t = table.column(t_col);
        if let Some(i) = (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            return Err(bad(
                table,
                format!(
                    "time does not increase at data row {} (t = {} after {}){}",
                    i + 1,
                    shown(t[i]),
                    shown(t[i - 1]),
                    time_hint(t[i], t[i - 1])
                ),
            ));
        }
        Ok((
            Self {
                table,
                joints,
                used,
            },
            t,
        ))
    }

    /// Row-major values of variable `var` for every joint; `None` when absent and optional.
    fn get(&mut self, var: &str, required: bool) -> Result<Option<Vec<f64>>> {
        let (table, joints, n) = (self.table, self.joints, self.joints.len());
        let cols: Vec<Option<usize>> = (0..n).map(|j| find(table, var, j, &joints[j])).collect();
        let found = cols.iter().filter(|c| c.is_some()).count();
        if found == 0 && !required {
            return Ok(None);
        }
        if found < n {
            let missing: Vec<String> = (0..n)
                .filter(|&j| cols[j].is_none())
                .map(|j| format!("{var}{} (or {var}_{})", j + 1, joints[j]))
                .collect();
            return Err(bad(
                table,
                format!(
                    "missing column(s) {}: the robot has {n} joints ({}); a log from another tool: read its own names as these with --column {var}=NAME_{{i}} ({{i}} the joint's index from 0, {{j}} its number, {{joint}} its name; Python columns=, docs/logs.md)",
                    missing.join(", "),
                    joints.join(", ")
                ),
            ));
        }
        let cols: Vec<usize> = cols.into_iter().map(|c| c.expect("checked")).collect();
        for &c in &cols {
            self.used[c] = true;
        }
        let w = table.columns.len();
        Ok(Some(
            (0..table.rows())
                .flat_map(|r| cols.iter().map(move |&c| table.values[r * w + c]))
                .collect(),
        ))
    }

    /// Fails on a column no `get` used.
    fn finish(self) -> Result<()> {
        let n = self.joints.len();
        match self.used.iter().position(|u| !u) {
            Some(c) => Err(bad(
                self.table,
                format!(
                    "unexpected column '{}': expected t, q1..q{n}, optional qd1..qd{n} and qdd1..qdd{n}, tau1..tau{n} (or the same named after the joints, e.g. q_{}); a log from another tool: leave its other columns out (command line --ignore-columns '{}', Python ignore_columns=) and read its own names as these (--column, columns=; docs/logs.md)",
                    self.table.columns[c], self.joints[0], self.table.columns[c]
                ),
            )),
            None => Ok(()),
        }
    }
}

fn bad(table: &Table, message: String) -> Error {
    Error::Recording {
        recording: table.source.clone(),
        message,
    }
}

/// Reads a recording of the joints `joints` from a CSV table: `t`, positions and torques
/// required; velocities and accelerations optional (all joints or none). Unknown columns are
/// an error naming them; so are missing ones, time that does not increase (with its row) and
/// fewer joints than the robot has.
pub fn read_recording(table: &Table, joints: &[String]) -> Result<Recording> {
    let (mut c, t) = Columns::new(table, joints)?;
    let q = c.get("q", true)?.expect("required");
    let qd = c.get("qd", false)?;
    let qdd = c.get("qdd", false)?;
    let tau = c.get("tau", true)?.expect("required");
    c.finish()?;
    Recording::new(table.source.clone(), joints.len(), t, q, tau, qd, qdd)
}

/// Reads the recording in the CSV file at `path` ([`read_recording`]; at most
/// [`MAX_TEXT_BYTES`](crate::limits::MAX_TEXT_BYTES)); named by its path, so a file named
/// after an experiment (`D.csv`) pairs with it in `identify_local`.
pub fn load_recording(path: &std::path::Path, joints: &[String]) -> Result<Recording> {
    read_recording(&Table::read(path)?, joints)
}

/// Writes `rec` to the CSV file at `path` ([`recording_table`]), atomically: a file that
/// [`load_recording`] reads back to the same numbers (what a preprocessed recording knows of
/// its log's glitches and dropouts is not kept).
pub fn save_recording(rec: &Recording, path: &std::path::Path) -> Result<()> {
    crate::io::write_atomic(path, recording_table(rec, "").to_csv().as_bytes())
}

/// States to evaluate a model at: `t`, `q`, `qd`, `qdd` required (row-major), `tau` optional
/// (measured torques to compare with).
pub struct States {
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Option<Vec<f64>>,
}

/// Reads [`States`] of the joints `joints` from a CSV table.
pub fn read_states(table: &Table, joints: &[String]) -> Result<States> {
    let (mut c, t) = Columns::new(table, joints)?;
    let q = c.get("q", true)?.expect("required");
    let qd = c.get("qd", true)?.expect("required");
    let qdd = c.get("qdd", true)?.expect("required");
    let tau = c.get("tau", false)?;
    c.finish()?;
    Ok(States { t, q, qd, qdd, tau })
}

fn header(var: &str, n: usize) -> impl Iterator<Item = String> + '_ {
    (1..=n).map(move |j| format!("{var}{j}"))
}

/// A recording as a table: `t, q1..qN, [qd1..qN, qdd1..qN,] tau1..tauN`.
pub fn recording_table(rec: &Recording, source: &str) -> Table {
    let n = rec.n;
    let mut columns = vec!["t".to_string()];
    columns.extend(header("q", n));
    if rec.qd.is_some() {
        columns.extend(header("qd", n));
    }
    if rec.qdd.is_some() {
        columns.extend(header("qdd", n));
    }
    columns.extend(header("tau", n));
    let mut t = Table::new(source, columns);
    for i in 0..rec.len() {
        let mut row = vec![rec.t[i]];
        row.extend_from_slice(&rec.q[i * n..(i + 1) * n]);
        for v in [&rec.qd, &rec.qdd].into_iter().flatten() {
            row.extend_from_slice(&v[i * n..(i + 1) * n]);
        }
        row.extend_from_slice(&rec.tau[i * n..(i + 1) * n]);
        t.push(&row);
    }
    t
}

/// Trajectory samples as a table: `t, q1..qN, qd1..qN, qdd1..qN`.
pub fn samples_table(s: &Samples, source: &str) -> Table {
    let n = s.n;
    let mut columns = vec!["t".to_string()];
    columns.extend(
        header("q", n)
            .chain(header("qd", n))
            .chain(header("qdd", n)),
    );
    let mut t = Table::new(source, columns);
    for i in 0..s.len() {
        let mut row = vec![s.t[i]];
        row.extend_from_slice(s.q_at(i));
        row.extend_from_slice(s.qd_at(i));
        row.extend_from_slice(s.qdd_at(i));
        t.push(&row);
    }
    t
}
