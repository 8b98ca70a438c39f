//! Writing files atomically: a temporary file beside the target, synced, then renamed.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::temporaries::{remove_stale_temporaries, temporary_name};
use crate::error::{Error, Result};

pub(crate) fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Writes `bytes` to a temporary file beside `path` (hidden, named after this process so that
/// a later run can remove it if this one is killed) and syncs it; returns its path. On failure
/// nothing is left behind.
pub(crate) fn write_temporary(path: &Path, bytes: &[u8]) -> Result<PathBuf> {
    let dir = folder_of(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(temporary_name(&name));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(io_error(path, e))
        }
    }
}

fn folder_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Writes `bytes` to `path` through a temporary file in the same folder, renamed into place
/// once complete: readers see the old file or the whole new one, never a part. Creates the
/// folder if needed and removes temporaries left there by killed runs. Several files that
/// belong together are written with [`super::OutputSet`] instead.
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> Result<()> {
    let path = path.as_ref();
    let dir = folder_of(path);
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    remove_stale_temporaries(dir);
    let tmp = write_temporary(path, bytes)?;
    if let Err(e) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_error(path, e));
    }
    Ok(())
}
