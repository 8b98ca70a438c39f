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

    /// The table in the CSV file at `path` (at most
    /// [`MAX_TEXT_BYTES`](crate::limits::MAX_TEXT_BYTES); see [`Self::parse`]); errors name
    /// the path.
    pub fn read(path: &std::path::Path) -> Result<Self> {
        Self::parse(&path.display().to_string(), &super::read_text(path)?)
    }

    /// Parses CSV text (RFC 4180 through the `csv` crate: quoted fields such as `"q1"` or
    /// `"a,b"` as other tools write them; a UTF-8 byte-order mark, blank lines and lines
    /// starting with `#` skipped). Every row must have one number per header column; a
    /// non-number, NaN or inf is an error naming the line (1-based) and the column, and so is
    /// a time (column `t`) that does not increase from one row to the next.
    pub fn parse(source: &str, text: &str) -> Result<Self> {
        Self::parse_selected(source, text, |columns| Ok(Selection::all(columns)))
    }

    /// [`Self::parse`] keeping the columns `select` picks from the header (after the header's
    /// own checks), under the names it gives them and scaled as it says: a column it leaves
    /// out is not read (it may hold text), a kept one must hold numbers whose scaled values are
    /// finite; the time that must increase is the kept column named `t`.
    pub fn parse_selected(
        source: &str,
        text: &str,
        select: impl FnOnce(&[String]) -> Result<Selection>,
    ) -> Result<Self> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let bad = |message: String| Error::Recording {
            recording: source.into(),
            message,
        };
        // Line numbers from byte offsets (the csv crate does not count the blank lines it
        // skips), counted incrementally: linear in the file. Records come in order.
        let lines = std::cell::Cell::new((0usize, 1usize));
        let line_at = |byte: u64| {
            let (from, line) = lines.get();
            let bytes = text.as_bytes();
            let mut to = (byte as usize).clamp(from, text.len());
            // a record's position is where the reader stood, before the blank lines it skipped
            while to < bytes.len() && matches!(bytes[to], b'\n' | b'\r') {
                to += 1;
            }
            let line = line + bytes[from..to].iter().filter(|&&b| b == b'\n').count();
            lines.set((to, line));
            line
        };
        let mut records = reader.records().filter_map(|r| match r {
            // blank (also whitespace only) and comment lines carry nothing
            Ok(rec) if rec.len() == 1 && rec[0].is_empty() => None,
            Ok(rec) if rec.get(0).is_some_and(|f| f.starts_with('#')) => None,
            Ok(rec) => {
                let line = rec.position().map_or(0, |p| line_at(p.byte()));
                Some(Ok((line, rec)))
            }
            Err(e) => Some(Err(e)),
        });
        let csv_error = |e: csv::Error| {
            let at = e
                .position()
                .map_or(String::new(), |p| format!("line {}: ", line_at(p.byte())));
            let what = match e.kind() {
                csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".to_string(),
                csv::ErrorKind::Io(io) => io.to_string(),
                _ => e.to_string(),
            };
            bad(format!("{at}{what}"))
        };
        let Some(first) = records.next() else {
            return Err(bad(
                "empty file: expected a header line of column names".into()
            ));
        };
        let (header_line, header) = first.map_err(csv_error)?;
        let columns: Vec<String> = header.iter().map(str::to_string).collect();
        let width = columns.len();
        let mut t = Table::new(source, columns);
        t.check_header(header_line)?;
        let selection = select(&t.columns)?;
        let original = std::mem::take(&mut t.columns);
        t.columns = selection.keep.iter().map(|k| k.name.clone()).collect();
        if let Some(problem) = t.header_problem() {
            return Err(t.error(format!(
                "line {header_line}, as the columns are renamed: {problem}"
            )));
        }
        // time must increase: checked here, where the line is known (a log whose clock
        // stepped back was named by its data row, which blank and comment lines shift)
        let time = t.index("t");
        let mut previous = (f64::NEG_INFINITY, 0);
        for record in records {
            let (line, fields) = record.map_err(csv_error)?;
            if fields.len() != width {
                return Err(t.error(format!(
                    "line {line}: {} fields, the header has {width} columns",
                    fields.len(),
                )));
            }
            for k in &selection.keep {
                let scaled = t.read_field(line, &fields[k.source], k, &original)?;
                t.values.push(scaled);
            }
            if let Some(c) = time {
                let now = t.values[t.values.len() - t.columns.len() + c];
                if now <= previous.0 {
                    return Err(t.error(format!(
                        "line {line}, column 't': time does not increase (t = {} after {} on line {}){}",
                        crate::error::shown(now),
                        crate::error::shown(previous.0),
                        previous.1,
                        time_hint(now, previous.0)
                    )));
                }
                previous = (now, line);
            }
        }
        if t.rows() == 0 {
            return Err(t.error("no data rows after the header".into()));
        }
        Ok(t)
    }

    /// Refuses a header that ends in a comma, names a column twice or not at all, or is one
    /// column whose name holds another separator.
    fn check_header(&self, header_line: usize) -> Result<()> {
        let t = self;
        if t.columns.len() > 1 && t.columns.last().is_some_and(String::is_empty) {
            // a logger that ends every line with a comma
            return Err(t.error(format!(
                "line {header_line}: column {}, the last, has no name: the line ends in a comma (remove the comma at the end of each line)",
                t.columns.len()
            )));
        }
        if let Some(problem) = t.header_problem() {
            return Err(t.error(format!("line {header_line}: {problem}")));
        }
        // a table written with another separator reads as one column
        if let [only] = t.columns.as_slice() {
            if let Some((sep, name)) = [
                (';', "semicolons"),
                ('\t', "tabs"),
                ('|', "bars"),
                (' ', "spaces"),
            ]
            .into_iter()
            .find(|(c, _)| only.contains(*c))
            {
                let shown: String = only.chars().take(60).collect();
                return Err(t.error(format!(
                    "line {header_line}: one column named '{}', its names separated by {name}: the columns must be separated by commas (replace each '{}' with ',', and a decimal comma with a point)",
                    shown.escape_debug(),
                    sep.escape_debug()
                )));
            }
        }
        Ok(())
    }

    /// The value of field `f` on line `line` for the kept column `k`, scaled (`original`: the
    /// file's column names); refuses a field that is not a finite number or whose scaled value
    /// is not finite.
    fn read_field(&self, line: usize, f: &str, k: &Kept, original: &[String]) -> Result<f64> {
        let t = self;
        // a column by its name in the file, and by the one it is read as where that differs
        let named = |k: &Kept| match &original[k.source] {
            name if *name == k.name => format!("'{name}'"),
            name => format!("'{name}' (read as {})", k.name),
        };
        let v: f64 = f.parse().map_err(|_| {
            // a column of words (a robot's mode, a date) is no recording's
            let words = if f.chars().any(|c| c.is_ascii_digit()) {
                String::new()
            } else {
                format!(
                    " (a column that holds no numbers is left out with --ignore-columns '{}', Python ignore_columns=)",
                    original[k.source]
                )
            };
            t.error(format!(
                "line {line}, column {}: '{f}' is not a number{words}",
                named(k)
            ))
        })?;
        if !v.is_finite() {
            return Err(t.error(format!(
                "line {line}, column {}: {v} is not a finite number",
                named(k)
            )));
        }
        let scaled = v * k.scale;
        if !scaled.is_finite() {
            return Err(t.error(format!(
                "line {line}, column {}: {} times {} is beyond the largest number",
                named(k),
                crate::error::shown(v),
                crate::error::shown(k.scale)
            )));
        }
        Ok(scaled)
    }

    /// A column named twice or not at all, if any. One pass with a set: a header of a million
    /// columns is checked in linear time.
    fn header_problem(&self) -> Option<String> {
        let mut seen = std::collections::HashSet::with_capacity(self.columns.len());
        if let Some(dup) = self.columns.iter().find(|c| !seen.insert(c.as_str())) {
            return Some(format!("column '{dup}' appears twice"));
        }
        let c = self.columns.iter().position(String::is_empty)?;
        Some(format!("column {} has no name", c + 1))
    }

    /// A table from named columns of equal length (another tool's table, such as a pandas
    /// DataFrame), checked as [`Self::parse`] checks a file: names present and distinct, at
    /// least one row, every value finite (an error names its row, 1-based, and column).
    pub fn from_columns(
        source: impl Into<String>,
        columns: Vec<(String, Vec<f64>)>,
    ) -> Result<Self> {
        let rows = columns.first().map_or(0, |c| c.1.len());
        let mut t = Table::new(source, columns.iter().map(|c| c.0.clone()).collect());
        if let Some(problem) = t.header_problem() {
            return Err(t.error(problem));
        }
        if let Some((name, v)) = columns.iter().find(|c| c.1.len() != rows) {
            return Err(t.error(format!(
                "column '{name}' has {} rows, column '{}' {rows}",
                v.len(),
                t.columns[0]
            )));
        }
        if rows == 0 {
            return Err(t.error("no data rows".into()));
        }
        t.values.reserve(rows * columns.len());
        for r in 0..rows {
            for (name, v) in &columns {
                if !v[r].is_finite() {
                    return Err(t.error(format!(
                        "row {}, column '{name}': {} is not a finite number",
                        r + 1,
                        v[r]
                    )));
                }
                t.values.push(v[r]);
            }
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
        let w = self.columns.len();
        csv_text(
            &self.columns,
            (0..self.rows()).map(|r| {
                self.values[r * w..(r + 1) * w]
                    .iter()
                    .map(|v| format!("{v}"))
            }),
        )
    }
}

/// A column [`Table::parse_selected`] keeps: its index in the file's header, the name it is
/// read as and the factor its values are multiplied by.
#[derive(Clone, Debug, PartialEq)]
pub struct Kept {
    pub source: usize,
    pub name: String,
    pub scale: f64,
}

/// The columns [`Table::parse_selected`] keeps, in the order the table holds them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    pub keep: Vec<Kept>,
}

impl Selection {
    /// Every column of `columns`, under its own name and unscaled.
    pub fn all(columns: &[String]) -> Self {
        Self {
            keep: (columns.iter().enumerate())
                .map(|(source, name)| Kept {
                    source,
                    name: name.clone(),
                    scale: 1.0,
                })
                .collect(),
        }
    }
}

/// CSV text (RFC 4180, through the `csv` crate: a field holding a comma, a quote or a line
/// break is quoted) of a header and rows of already formatted fields.
pub fn csv_text<H, R, F>(header: &[H], rows: impl IntoIterator<Item = R>) -> String
where
    H: AsRef<str>,
    R: IntoIterator<Item = F>,
    F: AsRef<str>,
{
    let mut w = csv::WriterBuilder::new()
        .flexible(true)
        .from_writer(Vec::new());
    // writing into memory cannot fail
    let _ = w.write_record(header.iter().map(|h| h.as_ref()));
    for row in rows {
        for f in row {
            let _ = w.write_field(f.as_ref());
        }
        let _ = w.write_record(None::<&[u8]>);
    }
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// Names for a message: the first `most`, then "...".
pub(crate) fn listed(columns: &[String], most: usize) -> String {
    let mut names: Vec<&str> = columns.iter().take(most).map(String::as_str).collect();
    if columns.len() > most {
        names.push("...");
    }
    names.join(", ")
}

/// What a time `now` that does not increase on `before` is likely to be, and what to do, for
/// messages (it begins with ": "): a repeated stamp (a message logged twice, or a clock
/// coarser than the rate) or a step back (logs joined end to end, rows out of order).
pub(crate) fn time_hint(now: f64, before: f64) -> &'static str {
    if now == before {
        ": a repeated time stamp (a message logged twice, or a clock coarser than the sample rate); drop the repeated rows, or give each its own time"
    } else {
        ": a step back (logs joined end to end, or rows out of order); split the log there, or sort its rows by time"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_what_other_tools_write() {
        // quoted names (pandas, spreadsheets), a byte-order mark, CRLF, comments and blanks
        let text =
            "\u{feff}\"t\",\"q,1\"\r\n# a comment\r\n\r\n  # indented comment\n0,1.5\n \n1,\"2\"\n";
        let t = Table::parse("x.csv", text).unwrap();
        assert_eq!(t.columns, ["t", "q,1"]);
        assert_eq!(t.values, [0.0, 1.5, 1.0, 2.0]);
        // and writes it back so that it reads the same
        assert_eq!(Table::parse("y.csv", &t.to_csv()).unwrap().values, t.values);
        assert!(t.to_csv().starts_with("t,\"q,1\"\n"));
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = Table::parse("x.csv", "t,q1\n0,1\n\n1,abc\n").unwrap_err();
        assert!(e.to_string().contains("line 4, column 'q1': 'abc'"), "{e}");
        let e = Table::parse("x.csv", "t,q1\n0,1,2\n").unwrap_err();
        assert!(e.to_string().contains("line 2: 3 fields"), "{e}");
        let e = Table::parse("x.csv", "t,\"q1\n0,1\n").unwrap_err();
        assert!(e.to_string().contains("x.csv"), "{e}");
        let e = Table::parse("x.csv", "t,,q\n0,1,2\n").unwrap_err();
        assert!(e.to_string().contains("column 2 has no name"), "{e}");
        let e = Table::parse("x.csv", "t,q1,\n0,1,\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("line 1: column 3, the last, has no name: the line ends in a comma"),
            "{e}"
        );
        // the line of a time that steps back, however many blank and comment lines before it
        let e = Table::parse("x.csv", "t,q1\n# log\n0,1\n\n0.5,1\n0.5,2\n").unwrap_err();
        assert!(
            e.to_string().contains(
                "line 6, column 't': time does not increase (t = 0.5 after 0.5 on line 5): a repeated time stamp"
            ),
            "{e}"
        );
    }

    #[test]
    fn columns_are_checked_as_a_file_is() {
        let col = |name: &str, v: &[f64]| (name.to_string(), v.to_vec());
        let t = Table::from_columns("df", vec![col("t", &[0.0, 1.0]), col("q1", &[2.0, 3.0])]);
        assert_eq!(t.unwrap().values, [0.0, 2.0, 1.0, 3.0]);
        let cases = [
            (
                vec![col("t", &[0.0]), col("t", &[1.0])],
                "column 't' appears twice",
            ),
            (
                vec![col("t", &[0.0]), col("", &[1.0])],
                "column 2 has no name",
            ),
            (
                vec![col("t", &[0.0, 1.0]), col("q1", &[1.0])],
                "column 'q1' has 1 rows, column 't' 2",
            ),
            (vec![col("t", &[]), col("q1", &[])], "no data rows"),
            (
                vec![col("t", &[0.0, 1.0]), col("q1", &[1.0, f64::NAN])],
                "row 2, column 'q1': NaN is not a finite number",
            ),
        ];
        for (columns, expected) in cases {
            let e = Table::from_columns("df", columns).unwrap_err().to_string();
            assert!(e.starts_with("df: ") && e.contains(expected), "{e}");
        }
    }
}
