//! The command line from Python: `perturbid` installed by pip runs the same Rust program.

use pyo3::prelude::*;

/// Runs the `perturbid` command line with `argv` (program name first); returns the exit status.
/// Output goes to the process's stdout and stderr.
#[pyfunction]
pub(crate) fn cli(py: Python<'_>, argv: Vec<String>) -> i32 {
    py.detach(|| crate::cli::main_with_args(argv))
}
