//! Configuration files in TOML (pipelines, studies), read into typed values with errors that
//! name the file, line and column.

use std::path::Path;

use serde::de::DeserializeOwned;

use crate::error::{Error, Result};

/// Line and column (1-based) of byte `offset` in `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let column = 1 + String::from_utf8_lossy(&before[start..]).chars().count();
    (line, column)
}

/// `source:line:column` of byte `offset` in `text`.
pub fn location(source: &str, text: &str, offset: usize) -> String {
    let (line, column) = line_col(text, offset);
    format!("{source}:{line}:{column}")
}

/// Parses TOML `text` (from `source`, for messages) into `T`; a syntax error, a missing or
/// unknown key or a value of the wrong type names the line and column. Text longer than
/// [`MAX_CONFIG_BYTES`](crate::limits::MAX_CONFIG_BYTES) is refused before parsing.
pub fn parse_toml<T: DeserializeOwned>(source: &str, text: &str) -> Result<T> {
    let max = crate::limits::MAX_CONFIG_BYTES;
    if text.len() > max {
        return Err(Error::Config {
            location: source.to_string(),
            message: format!(
                "{} bytes; a pipeline or study file is read up to {} KiB (a few kilobytes is usual; docs/limits.md)",
                text.len(),
                max >> 10
            ),
        });
    }
    toml::from_str(text).map_err(|e| {
        let mut message = e.message().trim().to_string();
        // the parser's "duplicate key" says where, not which: the key is the span's text
        let span = e.span().unwrap_or(0..0);
        let key = text.get(span.clone()).map(str::trim).unwrap_or("");
        if message == "duplicate key" && !key.is_empty() && key.len() <= 200 && !key.contains('\n')
        {
            let quoted = if key.starts_with(['"', '\'']) {
                key.to_string()
            } else {
                format!("'{key}'")
            };
            let table = text[..span.start].trim_end().ends_with('[');
            message = if table {
                format!("the table {quoted} is given twice; every table is given once")
            } else {
                format!("the key {quoted} is given twice in its table; every key is given once")
            };
        }
        Error::Config {
            location: match e.span() {
                Some(span) => location(source, text, span.start),
                None => source.to_string(),
            },
            message,
        }
    })
}

/// Reads and parses the TOML file `path` (size-bounded like every input, see
/// [`crate::io::read_text`]). Returns the text too, for the locations of later checks.
pub fn read_toml<T: DeserializeOwned>(path: &Path) -> Result<(T, String)> {
    let text = crate::io::read_document(path)?;
    Ok((parse_toml(&path.display().to_string(), &text)?, text))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Doc {
        a: f64,
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse_toml::<Doc>("p.toml", "\n\na = \"x\"\n").unwrap_err();
        assert!(e.to_string().starts_with("p.toml:3:5: "), "{e}");
        let e = parse_toml::<Doc>("p.toml", "a = 1.0\nb = 2\n").unwrap_err();
        assert!(e.to_string().starts_with("p.toml:2:1: "), "{e}");
        assert!(e.to_string().contains("unknown field `b`"), "{e}");
        let e = parse_toml::<Doc>("p.toml", "a = [\n").unwrap_err();
        assert!(e.to_string().starts_with("p.toml:1:"), "{e}");
        let huge = format!(
            "a = [{}1]\n",
            "1,".repeat(crate::limits::MAX_CONFIG_BYTES / 2)
        );
        let e = parse_toml::<Doc>("p.toml", &huge).unwrap_err();
        assert!(e.to_string().contains("read up to 1024 KiB"), "{e}");
        assert!(e.to_string().starts_with("p.toml:"), "{e}");
        assert_eq!(line_col("ab\ncd", 4), (2, 2));
        // a key given twice is named, as written
        let e = parse_toml::<Doc>("p.toml", "a = 1.0\n\"a\" = 2.0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "p.toml:2:1: the key \"a\" is given twice in its table; every key is given once"
        );
        let e = parse_toml::<Doc>("p.toml", "a = 1.0\n[b]\nx = 1\n[b]\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "p.toml:4:2: the table 'b' is given twice; every table is given once"
        );
    }
}
