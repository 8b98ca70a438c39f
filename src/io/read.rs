//! Reading text files: bounded in size, refused when they belong to an output set whose writing
//! was interrupted, or when they are of another format than text.

use std::path::Path;

use super::atomic::io_error;
use super::output_set::check_not_partial;
use crate::error::{Error, Result};

/// The contents of a text file (a table or log: at most
/// [`MAX_TEXT_BYTES`](crate::limits::MAX_TEXT_BYTES)); the error names the path. A file of
/// an output set whose writing was interrupted is refused ([`check_not_partial`]), and so is a
/// file of another format (a ROS bag, a Parquet file, ...), named with the way to a table.
pub fn read_text(path: impl AsRef<Path>) -> Result<String> {
    let path = path.as_ref();
    if let Some(message) = super::foreign::foreign_table(path) {
        return Err(Error::Recording {
            recording: path.display().to_string(),
            message,
        });
    }
    read_bounded(path, crate::limits::MAX_TEXT_BYTES, "table")
}

/// The contents of a document (JSON, TOML, URDF: at most
/// [`MAX_DOCUMENT_BYTES`](crate::limits::MAX_DOCUMENT_BYTES)), as [`read_text`], without the
/// UTF-8 byte-order mark an editor may have put first (JSON and TOML do not allow it; RFC 8259
/// lets a reader ignore it).
pub fn read_document(path: impl AsRef<Path>) -> Result<String> {
    let text = read_bounded(path.as_ref(), crate::limits::MAX_DOCUMENT_BYTES, "document")?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// Reads at most `max` bytes of `path` (`what` it is, for the error): a regular file larger
/// than that is refused before it is read, and a device or pipe (`/dev/zero`) is read no
/// further than the bound.
fn read_bounded(path: &Path, max: u64, what: &str) -> Result<String> {
    use std::io::Read;
    check_not_partial(path)?;
    let too_large = || {
        io_error(
            path,
            std::io::Error::other(format!(
                "larger than {} MB, the most read for a {what} (docs/limits.md)",
                max >> 20
            )),
        )
    };
    let file = std::fs::File::open(path).map_err(|e| io_error(path, e))?;
    let meta = file.metadata().map_err(|e| io_error(path, e))?;
    if meta.is_file() && meta.len() > max {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    if bytes.len() as u64 > max {
        return Err(too_large());
    }
    String::from_utf8(bytes).map_err(|e| not_utf8(path, e.as_bytes(), e.utf8_error()))
}

/// The error for `bytes` of `path` that are not UTF-8 text: where (line and byte), what byte,
/// and what the file might be instead.
fn not_utf8(path: &Path, bytes: &[u8], e: std::str::Utf8Error) -> Error {
    let at = e.valid_up_to();
    let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
    let column = at
        - bytes[..at]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1)
        + 1;
    let what = if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        "UTF-16 text (a byte-order mark of 0xff 0xfe or 0xfe 0xff first): save it as UTF-8"
    } else if bytes.iter().take(4096).any(|&b| b == 0) {
        "binary data, not text"
    } else {
        "text in another encoding (Latin-1 or Windows-1252, a degree sign or an accent in a name): save it as UTF-8"
    };
    io_error(
        path,
        std::io::Error::other(format!(
            "line {line}, byte {column} of it: byte 0x{:02x} is not UTF-8; the file looks like {what}",
            bytes[at]
        )),
    )
}
