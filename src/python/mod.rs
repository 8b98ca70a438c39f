//! The Python extension module `perturbid_rs._core` (pyo3). Only built with the `python`
//! feature, which maturin turns on. Thin: conversion of arguments and results, errors mapped
//! onto the Python exception hierarchy, the GIL released around Rust work.

mod arrays;
mod errors;
mod linearization;
mod robot;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<robot::PyRobot>()?;
    m.add_class::<linearization::PyLinearization>()?;
    errors::register(m)?;
    m.add_function(wrap_pyfunction!(robot::a465_urdf, m)?)?;
    Ok(())
}
