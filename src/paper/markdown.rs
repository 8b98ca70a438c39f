//! Markdown tables.

/// A Markdown table from a header and rows of cells.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = format!(
        "| {} |\n|{}\n",
        header.join(" | "),
        header.iter().map(|_| "---|").collect::<String>()
    );
    for r in rows {
        s.push_str(&format!("| {} |\n", r.join(" | ")));
    }
    s
}

/// Cells of numbers with `decimals` decimals (see [`number`]).
pub fn cells(values: &[f64], decimals: usize) -> Vec<String> {
    values.iter().map(|&v| number(v, decimals)).collect()
}

/// `v` with `decimals` decimals, without the sign of a value that rounds to zero (a mass-matrix
/// entry of 1e-17 prints as `0.000`, not `-0.000`).
pub fn number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn numbers_rounding_to_zero_have_no_sign() {
        assert_eq!(super::number(-1e-17, 3), "0.000");
        assert_eq!(super::number(-0.0004, 3), "0.000");
        assert_eq!(super::number(-0.0006, 3), "-0.001");
        assert_eq!(super::number(-2.5, 0), "-2");
        assert_eq!(super::number(f64::NAN, 2), "NaN");
    }
}
