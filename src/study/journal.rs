//! The study's journal, `cases.jsonl` in the output folder: one line per finished case,
//! appended (and flushed) as each case ends, so that a study stopped by Ctrl-C, a crash or a
//! lost worker resumes where it stopped: a rerun skips the cases whose id is in the journal.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::case::CaseResult;
use crate::error::{Error, Result};

/// The journal's file in `out`.
pub fn path(out: &Path) -> PathBuf {
    out.join("cases.jsonl")
}

/// The cases the journal in `out` holds, by id (none when there is no journal). A last line
/// cut short (the process stopped while writing it) is dropped; any other line that does not
/// read is an error naming the line.
pub fn read(out: &Path) -> Result<HashMap<String, CaseResult>> {
    let p = path(out);
    if !p.exists() {
        return Ok(HashMap::new());
    }
    let text = crate::io::read_text(&p)?;
    let lines: Vec<&str> = text.lines().collect();
    let mut done = HashMap::new();
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<CaseResult>(line) {
            Ok(r) => {
                done.insert(r.id.clone(), r);
            }
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => {} // cut short
            Err(e) => {
                return Err(Error::recording(
                    p.display().to_string(),
                    format!(
                        "line {}: not a case result ({e}); remove the line (its case is rerun) or the file (every case is rerun)",
                        i + 1
                    ),
                ))
            }
        }
    }
    Ok(done)
}

/// Appends finished cases to the journal in `out` (created with the folder if needed).
pub fn append(out: &Path, results: &[CaseResult]) -> Result<()> {
    let io = |e: std::io::Error| Error::Io {
        path: path(out).display().to_string(),
        source: e,
    };
    std::fs::create_dir_all(out).map_err(io)?;
    let p = path(out);
    // a line cut short by an earlier stop is removed first (its case is rerun)
    cut_partial_line(&p).map_err(io)?;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&p)
        .map_err(io)?;
    let mut text = String::new();
    for r in results {
        text.push_str(&serde_json::to_string(r).expect("serialisable"));
        text.push('\n');
    }
    f.write_all(text.as_bytes()).map_err(io)?;
    f.sync_data().map_err(io)
}

/// Truncates `p` after its last line break when its last line is cut short (checks one byte
/// unless it is).
fn cut_partial_line(p: &Path) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let Ok(mut f) = std::fs::OpenOptions::new().read(true).write(true).open(p) else {
        return Ok(()); // no journal yet
    };
    let len = f.metadata()?.len();
    if len == 0 {
        return Ok(());
    }
    let mut last = [0u8];
    f.seek(SeekFrom::Start(len - 1))?;
    f.read_exact(&mut last)?;
    if last[0] == b'\n' {
        return Ok(());
    }
    let bytes = std::fs::read(p)?;
    let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    f.set_len(keep as u64)
}
