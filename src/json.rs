//! JSON helpers shared by the saved plans and models: matrices as lists of rows, so a person can
//! read them and other tools can load them.

/// Serde adapter for `nalgebra::DMatrix<f64>` as a list of rows (`[[a11, a12], [a21, a22]]`).
pub mod rows {
    use nalgebra::DMatrix;
    use serde::{de::Error as _, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(m: &DMatrix<f64>, s: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<Vec<f64>> = m.row_iter().map(|r| r.iter().copied().collect()).collect();
        rows.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DMatrix<f64>, D::Error> {
        let rows = Vec::<Vec<f64>>::deserialize(d)?;
        from_rows(&rows).map_err(D::Error::custom)
    }

    /// A matrix from rows of equal length.
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<DMatrix<f64>, String> {
        let ncols = rows.first().map_or(0, Vec::len);
        if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != ncols) {
            return Err(format!(
                "matrix row {} has {} entries, row 1 has {}",
                i + 1,
                r.len(),
                ncols
            ));
        }
        Ok(DMatrix::from_fn(rows.len(), ncols, |i, j| rows[i][j]))
    }
}

/// Serde adapter for `Option<DMatrix<f64>>` as a list of rows or `null`.
pub mod option_rows {
    use nalgebra::DMatrix;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(m: &Option<DMatrix<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match m {
            Some(m) => super::rows::serialize(m, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<DMatrix<f64>>, D::Error> {
        let rows = Option::<Vec<Vec<f64>>>::deserialize(d)?;
        rows.map(|r| super::rows::from_rows(&r).map_err(serde::de::Error::custom))
            .transpose()
    }
}

/// Serde adapter for matrices of standard errors as lists of rows, where an unknown standard
/// error (NaN: no residual degree of freedom) is `null`; `null` reads back as NaN. Only for
/// standard errors: a `null` anywhere else is refused.
pub mod stderr_rows {
    use nalgebra::DMatrix;
    use serde::{de::Error as _, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(m: &DMatrix<f64>, s: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<Vec<Option<f64>>> = m
            .row_iter()
            .map(|r| r.iter().map(|v| v.is_finite().then_some(*v)).collect())
            .collect();
        rows.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DMatrix<f64>, D::Error> {
        let rows = Vec::<Vec<Option<f64>>>::deserialize(d)?;
        let rows: Vec<Vec<f64>> = rows
            .into_iter()
            .map(|r| r.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            .collect();
        super::rows::from_rows(&rows).map_err(D::Error::custom)
    }
}

/// Serde adapter for vectors of standard errors, `null` for an unknown one (see
/// [`stderr_rows`]).
pub mod stderr_vec {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        let v: Vec<Option<f64>> = v.iter().map(|x| x.is_finite().then_some(*x)).collect();
        v.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let v = Vec::<Option<f64>>::deserialize(d)?;
        Ok(v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
    }
}

/// An empty matrix (0 x 0): the default of a matrix field a document saved before it existed.
pub fn empty_matrix() -> nalgebra::DMatrix<f64> {
    nalgebra::DMatrix::zeros(0, 0)
}

/// Whether a matrix field is empty (not written).
pub fn is_empty_matrix(m: &nalgebra::DMatrix<f64>) -> bool {
    m.is_empty()
}

/// Serde adapter for a list of matrices (`Vec<DMatrix<f64>>`), each a list of rows.
pub mod matrices {
    use nalgebra::DMatrix;
    use serde::{de::Error as _, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(m: &[DMatrix<f64>], s: S) -> Result<S::Ok, S::Error> {
        let all: Vec<Vec<Vec<f64>>> = m
            .iter()
            .map(|m| m.row_iter().map(|r| r.iter().copied().collect()).collect())
            .collect();
        all.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<DMatrix<f64>>, D::Error> {
        let all = Vec::<Vec<Vec<f64>>>::deserialize(d)?;
        all.iter()
            .enumerate()
            .map(|(i, rows)| {
                super::rows::from_rows(rows)
                    .map_err(|e| D::Error::custom(format!("matrix {}: {e}", i + 1)))
            })
            .collect()
    }
}

/// Refuses JSON `text` (from `context`, for the message) holding more than
/// [`MAX_JSON_CONTAINERS`](crate::limits::MAX_JSON_CONTAINERS) arrays and objects, before any
/// parser allocates them: each costs the parser about 80 bytes for its 4 of text (`[0],`), so a
/// document of the byte bound in empty rows would take gigabytes. One pass; brackets inside
/// strings are not counted.
pub(crate) fn check_containers(text: &str, context: &str) -> crate::error::Result<()> {
    let max = crate::limits::MAX_JSON_CONTAINERS;
    let (mut count, mut in_string, mut escaped) = (0usize, false, false);
    for (i, &b) in text.as_bytes().iter().enumerate() {
        if in_string {
            match b {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => in_string = false,
                _ => {}
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                count += 1;
                if count > max {
                    let line = 1 + text.as_bytes()[..i].iter().filter(|&&c| c == b'\n').count();
                    return Err(crate::error::Error::Json {
                        context: context.to_string(),
                        message: format!(
                            "line {line}: more than {max} arrays and objects; a document of the largest robot has some tens of thousands (docs/limits.md)"
                        ),
                    });
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// A serde_json error as `line L, column C: what` without serde's trailing repetition of the
/// position, with a hint where the text holds a number JSON cannot spell (`NaN`, `Infinity`,
/// as Python's `json` module writes them). `text` is the document that was parsed.
pub(crate) fn describe_error(e: &serde_json::Error, text: &str) -> String {
    describe_error_at(e, text, "")
}

/// [`describe_error`] with the JSON path of the culprit (`experiments[2].rate`; none if empty)
/// after the position.
pub(crate) fn describe_error_at(e: &serde_json::Error, text: &str, path: &str) -> String {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let what = full.strip_suffix(&suffix).unwrap_or(&full);
    let hint = if e.is_syntax() && non_json_number_at(text, e.line(), e.column()) {
        " (JSON has no NaN or Infinity: write a finite number, or null where a value may be unknown)"
    } else {
        ""
    };
    let at = if path.is_empty() {
        String::new()
    } else {
        format!(", at {path}")
    };
    format!("line {}, column {}{at}: {what}{hint}", e.line(), e.column())
}

/// Whether the text at 1-based `line` and `column` (serde_json's position of a syntax error:
/// the first character it could not read) starts a `NaN` or `[-]Infinity` literal.
fn non_json_number_at(text: &str, line: usize, column: usize) -> bool {
    let Some(l) = text.lines().nth(line.saturating_sub(1)) else {
        return false;
    };
    // from the character before the position (a minus sign), on character boundaries
    let window: String = l
        .chars()
        .skip(column.saturating_sub(2))
        .take(10)
        .collect::<String>()
        .to_ascii_lowercase();
    let literal = window.trim_start_matches(|c: char| !c.is_ascii_alphabetic());
    literal.starts_with("nan") || literal.starts_with("inf")
}
