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

/// Cells of numbers with `decimals` decimals.
pub fn cells(values: &[f64], decimals: usize) -> Vec<String> {
    values.iter().map(|v| format!("{v:.decimals$}")).collect()
}
