//! The temporary files an atomic write leaves beside its target until it renames them, named
//! after the process that wrote them, and their removal once that process is gone.

use std::path::Path;
use std::time::{Duration, SystemTime};

/// A temporary file older than this is stale even if a process with its id runs.
const STALE_AFTER: Duration = Duration::from_secs(3600);

/// The name of the temporary file for `path` written by this process.
pub(crate) fn temporary_name(file_name: &str) -> String {
    format!(".{file_name}.perturbid-{}.tmp", std::process::id())
}

/// The process id in a temporary file name written by [`temporary_name`] (or by earlier
/// versions, `.NAME.PID.tmp`), if `name` is one.
pub(crate) fn temporary_pid(name: &str) -> Option<u32> {
    let stem = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (_, pid) = stem.rsplit_once('.')?;
    let pid = pid.strip_prefix("perturbid-").unwrap_or(pid);
    pid.parse().ok()
}

/// Removes temporaries in `dir` left by runs that were killed: their process is gone (checked
/// in `/proc` where there is one) or they are older than an hour. Errors are ignored: this is
/// housekeeping.
pub(crate) fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let proc = Path::new("/proc/self").exists();
    let me = std::process::id();
    for e in entries.filter_map(|e| e.ok()) {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = temporary_pid(&name) else {
            continue;
        };
        if pid == me {
            continue;
        }
        let dead = proc && !Path::new(&format!("/proc/{pid}")).exists();
        let old = e
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| SystemTime::now().duration_since(t).ok())
            .is_some_and(|age| age > STALE_AFTER);
        if dead || old {
            let _ = std::fs::remove_file(e.path());
        }
    }
}
