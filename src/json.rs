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
