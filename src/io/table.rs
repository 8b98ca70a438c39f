//! Numeric CSV tables: a header line of column names, then rows of numbers.

use crate::error::{Error, Result};

/// A table of numbers with named columns, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Where it came from (a path), for messages.
    pub source: String,
    pub columns: Vec<String>,
    /// `rows x columns.len()` values, row after row.
    pub values: Vec<f64>,
}

impl Table {
    pub fn new(source: impl Into<String>, columns: Vec<String>) -> Self {
        Self {
            source: source.into(),
            columns,
            values: Vec::new(),
        }
    }

    pub fn rows(&self) -> usize {
        self.values.len() / self.columns.len().max(1)
    }

    fn error(&self, message: String) -> Error {
        Error::Recording {
            recording: self.source.clone(),
            message,
        }
    }

    /// Parses CSV text (comma separated; blank lines and lines starting with `#` skipped). Every
    /// row must have one number per header column; a non-number, NaN or inf is an error naming
    /// the line (1-based) and the column.
    pub fn parse(source: &str, text: &str) -> Result<Self> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((header_line, header)) = lines.next() else {
            return Err(Error::Recording {
                recording: source.into(),
                message: "empty file: expected a header line of column names".into(),
            });
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let mut t = Table::new(source, columns);
        // one pass with a set: a header of a million columns is read in linear time
        let mut seen = std::collections::HashSet::with_capacity(t.columns.len());
        if let Some(dup) = t.columns.iter().find(|c| !seen.insert(c.as_str())) {
            return Err(t.error(format!(
                "line {}: column '{dup}' appears twice",
                header_line + 1
            )));
        }
        for (i, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != t.columns.len() {
                return Err(t.error(format!(
                    "line {}: {} fields, the header has {} columns",
                    i + 1,
                    fields.len(),
                    t.columns.len()
                )));
            }
            for (c, f) in fields.iter().enumerate() {
                let v: f64 = f.trim().parse().map_err(|_| {
                    t.error(format!(
                        "line {}, column '{}': '{}' is not a number",
                        i + 1,
                        t.columns[c],
                        f.trim()
                    ))
                })?;
                if !v.is_finite() {
                    return Err(t.error(format!(
                        "line {}, column '{}': {v} is not a finite number",
                        i + 1,
                        t.columns[c]
                    )));
                }
                t.values.push(v);
            }
        }
        if t.rows() == 0 {
            return Err(t.error("no data rows after the header".into()));
        }
        Ok(t)
    }

    /// The column named `name`, if present.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// The values of column `c`.
    pub fn column(&self, c: usize) -> Vec<f64> {
        let w = self.columns.len();
        (0..self.rows()).map(|r| self.values[r * w + c]).collect()
    }

    /// Appends a row (its length must match the columns).
    pub fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.columns.len());
        self.values.extend_from_slice(row);
    }

    /// CSV text: the header, then the rows with full precision (shortest round-trip form).
    pub fn to_csv(&self) -> String {
        let mut out = self.columns.join(",");
        out.push('\n');
        let w = self.columns.len();
        for r in 0..self.rows() {
            let row: Vec<String> = self.values[r * w..(r + 1) * w]
                .iter()
                .map(|v| format!("{v}"))
                .collect();
            out.push_str(&row.join(","));
            out.push('\n');
        }
        out
    }
}
