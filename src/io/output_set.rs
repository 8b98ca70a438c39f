//! Output sets: several files written together (a plan and its trajectories, the recordings of
//! a plan, an excitation as JSON and CSV, the paper's report) so that a reader sees either the
//! whole old set or the whole new one.
//!
//! A set named `S` in folder `D` is described by `D/S.manifest.json`:
//!
//! ```json
//! {"format": "perturbid.manifest", "version": 1, "set": "S", "state": "complete",
//!  "files": ["a.csv", "b.csv"], "replacing": []}
//! ```
//!
//! [`OutputSet::commit`] writes every file to a temporary file first (a failure or Ctrl-C there
//! leaves the old set untouched), then marks the manifest `"writing"` (listing the new files and
//! the old ones they replace), renames the temporaries into place, removes the old set's files
//! that the new one does not have, and marks the manifest `"complete"`. A run killed between the
//! two manifest writes leaves a manifest in state `"writing"`: [`check_not_partial`], called by
//! every reader of this library, refuses the files it lists, since they may mix old and new.
//! Temporaries left by killed runs (`.NAME.perturbid-PID.tmp`) are removed by the next write
//! into the folder once their process is gone (or after an hour).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

use super::atomic::{io_error, write_temporary};
use super::temporaries::remove_stale_temporaries;

const FORMAT: &str = "perturbid.manifest";
const SUFFIX: &str = ".manifest.json";
/// A manifest larger than this is not one of ours (it is not read when checking a file).
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
struct Manifest {
    format: String,
    version: u32,
    set: String,
    /// `"writing"` while files are being renamed into place, `"complete"` after.
    state: String,
    files: Vec<String>,
    #[serde(default)]
    replacing: Vec<String>,
}

impl Manifest {
    fn path(dir: &Path, set: &str) -> PathBuf {
        dir.join(format!("{set}{SUFFIX}"))
    }

    /// The manifest at `path`, or `None` if there is none or it is not one of ours.
    fn read(path: &Path) -> Option<Manifest> {
        let meta = std::fs::metadata(path).ok()?;
        if !meta.is_file() || meta.len() > MAX_MANIFEST_BYTES {
            return None;
        }
        let text = std::fs::read_to_string(path).ok()?;
        let m: Manifest = serde_json::from_str(&text).ok()?;
        (m.format == FORMAT).then_some(m)
    }

    fn lists(&self, name: &str) -> bool {
        self.files.iter().chain(&self.replacing).any(|f| f == name)
    }
}

/// Files to be written together into one folder; see the module documentation.
pub struct OutputSet {
    dir: PathBuf,
    set: String,
    files: Vec<(String, Vec<u8>)>,
}

impl OutputSet {
    /// A set named `set` (the manifest is `dir/<set>.manifest.json`) in folder `dir`, created
    /// on commit if needed.
    pub fn new(dir: impl Into<PathBuf>, set: &str) -> OutputSet {
        OutputSet {
            dir: dir.into(),
            set: set.to_string(),
            files: vec![],
        }
    }

    /// Adds the file `name` (a plain file name in the set's folder) with its contents.
    ///
    /// Errors: a name with a path separator, empty, `.`/`..`, hidden, a manifest name, or a
    /// name already in the set.
    pub fn add(&mut self, name: &str, bytes: impl Into<Vec<u8>>) -> Result<&mut OutputSet> {
        let bad = |why: &str| Error::invalid("output file name", format!("'{name}' {why}"));
        if !is_plain_name(name) {
            return Err(bad(
                "must be a plain, visible file name (no folder, not hidden)",
            ));
        }
        if name.ends_with(SUFFIX) {
            return Err(bad("is reserved for output manifests"));
        }
        if self.files.iter().any(|(n, _)| n == name) {
            return Err(bad(&format!(
                "is written twice in the output set '{}'",
                self.set
            )));
        }
        self.files.push((name.to_string(), bytes.into()));
        Ok(self)
    }

    /// The path a file of the set will have.
    pub fn path_of(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes the set (see the module documentation) and returns the paths of its files, in the
    /// order they were added.
    ///
    /// Errors: [`Error::Io`] naming the file that could not be written (the old set is then
    /// intact if the failure came before the renames); [`Error::InvalidArgument`] if a file
    /// would overwrite a file of another output set in the same folder (for example the
    /// recordings of a plan written over the plan's trajectories: choose another folder).
    pub fn commit(self) -> Result<Vec<PathBuf>> {
        let dir = if self.dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            self.dir.clone()
        };
        std::fs::create_dir_all(&dir).map_err(|e| io_error(&dir, e))?;
        remove_stale_temporaries(&dir);
        self.refuse_other_sets(&dir)?;
        let manifest_path = Manifest::path(&dir, &self.set);
        let old = Manifest::read(&manifest_path);

        // 1. Every file to a temporary: nothing visible changes yet.
        let mut temps: Vec<PathBuf> = vec![];
        for (name, bytes) in &self.files {
            match write_temporary(&dir.join(name), bytes) {
                Ok(t) => temps.push(t),
                Err(e) => {
                    for t in &temps {
                        let _ = std::fs::remove_file(t);
                    }
                    return Err(e);
                }
            }
        }
        let names: Vec<String> = self.files.iter().map(|(n, _)| n.clone()).collect();
        let new_set: BTreeSet<&str> = names.iter().map(String::as_str).collect();
        let stale: Vec<String> = old
            .map(|m| {
                let mut v = m.files;
                v.extend(m.replacing);
                v.retain(|f| !new_set.contains(f.as_str()) && is_plain_name(f));
                v.sort();
                v.dedup();
                v
            })
            .unwrap_or_default();
        let mut manifest = Manifest {
            format: FORMAT.into(),
            version: 1,
            set: self.set.clone(),
            state: "writing".into(),
            files: names.clone(),
            replacing: stale.clone(),
        };
        // 2. Mark the set as being written, 3. swap the files in, 4. drop the old extras.
        let swap = (|| -> Result<()> {
            write_manifest(&manifest_path, &manifest)?;
            for ((name, _), tmp) in self.files.iter().zip(&temps) {
                let path = dir.join(name);
                std::fs::rename(tmp, &path).map_err(|e| io_error(&path, e))?;
            }
            for name in &stale {
                let path = dir.join(name);
                match std::fs::remove_file(&path) {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    Err(e) => return Err(io_error(&path, e)),
                }
            }
            Ok(())
        })();
        if let Err(e) = swap {
            for t in &temps {
                let _ = std::fs::remove_file(t);
            }
            return Err(e);
        }
        // 5. The set is whole.
        manifest.state = "complete".into();
        manifest.replacing.clear();
        write_manifest(&manifest_path, &manifest)?;
        Ok(names.iter().map(|n| self.dir.join(n)).collect())
    }

    fn refuse_other_sets(&self, dir: &Path) -> Result<()> {
        for (other_path, other) in manifests_in(dir) {
            if other.set == self.set {
                continue;
            }
            if let Some((name, _)) = self.files.iter().find(|(n, _)| other.lists(n)) {
                return Err(Error::invalid(
                    "output folder",
                    format!(
                        "{} belongs to the output set '{}' ({}); writing the set '{}' there would replace it: choose another output folder",
                        dir.join(name).display(),
                        other.set,
                        other_path.display(),
                        self.set
                    ),
                ));
            }
        }
        Ok(())
    }
}

fn is_plain_name(name: &str) -> bool {
    !name.is_empty() && !name.starts_with('.') && !name.contains(['/', '\\', '\0'])
}

fn write_manifest(path: &Path, m: &Manifest) -> Result<()> {
    let text = serde_json::to_string_pretty(m).expect("a manifest always serialises");
    super::atomic::write_atomic(path, text.as_bytes())
}

/// The manifests in `dir` (bounded: folders are listed once, manifests above 16 MiB or not
/// ours are skipped).
fn manifests_in(dir: &Path) -> Vec<(PathBuf, Manifest)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return vec![];
    };
    entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(SUFFIX))
        .filter_map(|e| {
            let p = e.path();
            Manifest::read(&p).map(|m| (p, m))
        })
        .collect()
}

/// Refuses to read `path` if it belongs to an output set whose writing was interrupted (a
/// manifest in its folder in state `"writing"` lists it): the set may mix old and new files.
///
/// Errors: [`Error::PartialOutput`] naming the file and the manifest.
pub fn check_not_partial(path: &Path) -> Result<()> {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Ok(());
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    for (manifest_path, m) in manifests_in(dir) {
        if m.state != "complete" && m.lists(&name) {
            return Err(Error::PartialOutput {
                path: path.display().to_string(),
                manifest: manifest_path.display().to_string(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::temporaries::{temporary_name, temporary_pid};

    fn tmpdir(tag: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("perturbid-output-set-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn temporary_names_round_trip() {
        assert_eq!(
            temporary_pid(&temporary_name("a.csv")),
            Some(std::process::id())
        );
        assert_eq!(temporary_pid(".a.csv.123.tmp"), Some(123));
        assert_eq!(temporary_pid("a.csv"), None);
        assert_eq!(temporary_pid(".a.csv.x.tmp"), None);
    }

    #[test]
    fn a_new_set_replaces_the_old_one_whole() {
        let d = tmpdir("replace");
        let mut s = OutputSet::new(&d, "run");
        s.add("a.csv", "old a").unwrap();
        s.add("b.csv", "old b").unwrap();
        s.commit().unwrap();
        let mut s = OutputSet::new(&d, "run");
        s.add("a.csv", "new a").unwrap();
        s.add("c.csv", "new c").unwrap();
        let paths = s.commit().unwrap();
        assert_eq!(paths, vec![d.join("a.csv"), d.join("c.csv")]);
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "new a");
        assert!(!d.join("b.csv").exists(), "the old set's extra file stays");
        let m = Manifest::read(&d.join("run.manifest.json")).unwrap();
        assert_eq!(m.state, "complete");
        assert_eq!(m.files, vec!["a.csv", "c.csv"]);
        check_not_partial(&d.join("a.csv")).unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_interrupted_set_is_refused_by_readers() {
        let d = tmpdir("partial");
        let mut s = OutputSet::new(&d, "run");
        s.add("a.csv", "x").unwrap();
        s.commit().unwrap();
        // what a run killed between the renames leaves
        let m = Manifest {
            format: FORMAT.into(),
            version: 1,
            set: "run".into(),
            state: "writing".into(),
            files: vec!["a.csv".into()],
            replacing: vec!["b.csv".into()],
        };
        write_manifest(&d.join("run.manifest.json"), &m).unwrap();
        let e = check_not_partial(&d.join("a.csv")).unwrap_err();
        assert!(matches!(e, Error::PartialOutput { .. }));
        assert!(e.to_string().contains("run.manifest.json"), "{e}");
        assert!(check_not_partial(&d.join("b.csv")).is_err());
        check_not_partial(&d.join("other.csv")).unwrap();
        // writing the set again repairs it
        let mut s = OutputSet::new(&d, "run");
        s.add("a.csv", "y").unwrap();
        s.commit().unwrap();
        check_not_partial(&d.join("a.csv")).unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn stale_temporaries_are_removed_live_ones_kept() {
        let d = tmpdir("stale");
        // pid 2^31 - 2 does not run
        let dead = d.join(".a.csv.perturbid-2147483646.tmp");
        let legacy = d.join(".b.csv.2147483646.tmp");
        let mine = d.join(temporary_name("c.csv"));
        for p in [&dead, &legacy, &mine] {
            std::fs::write(p, "x").unwrap();
        }
        let mut s = OutputSet::new(&d, "run");
        s.add("a.csv", "x").unwrap();
        s.commit().unwrap();
        assert!(!dead.exists() && !legacy.exists());
        assert!(mine.exists(), "a temporary of a running process is kept");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn another_sets_files_are_not_overwritten() {
        let d = tmpdir("other");
        let mut s = OutputSet::new(&d, "plan");
        s.add("D.csv", "trajectory").unwrap();
        s.commit().unwrap();
        let mut s = OutputSet::new(&d, "recordings");
        s.add("D.csv", "recording").unwrap();
        let e = s.commit().unwrap_err().to_string();
        assert!(e.contains("belongs to the output set 'plan'"), "{e}");
        assert_eq!(
            std::fs::read_to_string(d.join("D.csv")).unwrap(),
            "trajectory"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn bad_names_are_refused() {
        let mut s = OutputSet::new("x", "run");
        for bad in ["", ".hidden", "a/b", "..", "x.manifest.json"] {
            assert!(s.add(bad, "").is_err(), "{bad:?}");
        }
        s.add("a", "").unwrap();
        assert!(s.add("a", "").is_err());
    }
}
