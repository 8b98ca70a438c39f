//! The command line from Python: `perturbid` installed by pip runs the same Rust program.

use pyo3::prelude::*;

/// Runs the `perturbid` command line with `argv` (program name first); returns the exit status.
/// Output goes to the process's stdout and stderr. Arguments are OS strings, so file names that
/// are not valid UTF-8 (Python hands them over surrogate-escaped) reach the program intact.
#[pyfunction]
pub(crate) fn cli(py: Python<'_>, argv: Vec<std::ffi::OsString>) -> i32 {
    py.detach(|| crate::cli::main_with_args(argv))
}
