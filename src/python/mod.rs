//! The Python extension module `perturbid_rs._core` (pyo3). Only built with the `python`
//! feature, which maturin turns on. Thin: conversion of arguments and results, errors mapped
//! onto the Python exception hierarchy, the GIL released around Rust work.

mod arrays;
mod cli;
mod consistent;
mod direct;
mod drive_gains;
mod errors;
mod excitation;
mod findings;
mod global_linear;
mod linearization;
mod local;
mod local_model;
mod noise;
mod operating_point;
mod payload;
mod payload_argument;
mod preprocess;
mod recording;
mod recording_list;
mod rehearsal;
mod robot;
mod samples;
mod scalars;
mod simulation;
mod study;
mod tables;
mod trajectory;
mod validation;

use pyo3::prelude::*;

use crate::error::{catch_panics, Result};

/// Runs the Rust work `f` of the Python entry point `name` with the GIL released, a panic
/// turned into `InternalError` naming `name` (never a bare `PanicException`).
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    name: &str,
    f: impl FnOnce() -> Result<T> + Send,
) -> Result<T> {
    crate::interrupt::reset();
    py.detach(|| catch_panics(name, f))
}

/// The instruction set the batched kernels run on here: "avx512" (8 samples side by side),
/// "avx2+fma" (4) or "scalar" (one at a time); `PERTURBID_SIMD` caps it (`Isa::detect`).
#[pyfunction]
fn simd_isa() -> &'static str {
    crate::simd::Isa::detect().name()
}

/// Python's own signal check, for [`crate::interrupt`]: a Ctrl-C in the session is seen while
/// Rust works with the GIL released (its `KeyboardInterrupt` is raised by the work's error).
fn python_interrupted() -> bool {
    Python::attach(|py| py.check_signals().is_err())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    crate::interrupt::set_checker(python_interrupted);
    // Rust's `log` records go to Python's `logging` (logger names follow the targets:
    // `perturbid_rs.excitation`, `perturbid_rs.study`, ...); already installed is fine.
    let _ = pyo3_log::try_init();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(simd_isa, m)?)?;
    m.add_class::<robot::PyRobot>()?;
    m.add_function(wrap_pyfunction!(study::study_resolve, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_resolve_file, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_len, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_pending, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_case, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_record, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_finish, m)?)?;
    m.add_function(wrap_pyfunction!(study::study_run, m)?)?;
    m.add_class::<linearization::PyLinearization>()?;
    m.add_class::<operating_point::PyOperatingPoint>()?;
    m.add_class::<local::PyPlan>()?;
    m.add_class::<local::PyExperiment>()?;
    m.add_class::<recording::PyRecording>()?;
    m.add_class::<local_model::PyLocalModel>()?;
    m.add_function(wrap_pyfunction!(local::plan_experiments, m)?)?;
    m.add_function(wrap_pyfunction!(simulation::simulate, m)?)?;
    m.add_class::<rehearsal::PyTrueRobot>()?;
    m.add_function(wrap_pyfunction!(local::identify_local, m)?)?;
    m.add_function(wrap_pyfunction!(local::identify_parameters_from_local, m)?)?;
    m.add_function(wrap_pyfunction!(local::suggest_operating_points, m)?)?;
    m.add_class::<trajectory::PyFourier>()?;
    m.add_class::<excitation::PyExcitationDesign>()?;
    m.add_class::<direct::PyBaseModel>()?;
    m.add_class::<global_linear::PyGlobalLinear>()?;
    m.add_function(wrap_pyfunction!(excitation::design_excitation, m)?)?;
    m.add_function(wrap_pyfunction!(direct::identify_base_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(drive_gains::identify_drive_gains, m)?)?;
    m.add_class::<payload::PyPayloadFit>()?;
    m.add_function(wrap_pyfunction!(payload::identify_payload, m)?)?;
    m.add_function(wrap_pyfunction!(global_linear::identify_global_linear, m)?)?;
    m.add_class::<consistent::PyConsistentFit>()?;
    m.add_class::<validation::PyValidation>()?;
    m.add_function(wrap_pyfunction!(validation::validate, m)?)?;
    m.add_function(wrap_pyfunction!(
        consistent::identify_consistent_parameters,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(preprocess::preprocess, m)?)?;
    m.add_function(wrap_pyfunction!(cli::cli, m)?)?;
    errors::register(m)?;
    m.add_function(wrap_pyfunction!(robot::a465_urdf, m)?)?;
    Ok(())
}
