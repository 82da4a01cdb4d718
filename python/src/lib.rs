//! `mergesim._native`: the Rust half of the `mergesim` Python package (python/README.md).
//! Scenarios load as in `merge_sim` (built-in name, path, or TOML text); bad input raises
//! `ScenarioError` with the CLI's message; the simulations run without the GIL.
//!
//! # Public API
//! None in Rust (every module is private): the API is the Python module `mergesim._native`,
//! whose functions and classes `_native` registers.

mod background;
mod env_agents;
mod env_core;
mod errors;
mod external;
mod py_planner;
mod road;
mod run;
mod source;
mod study;
mod sweep;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ScenarioError", py.get_type::<errors::ScenarioError>())?;
    m.add("SimulationError", py.get_type::<errors::SimulationError>())?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(study::study, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(planners, m)?)?;
    m.add_function(wrap_pyfunction!(instance_seed, m)?)?;
    m.add_function(wrap_pyfunction!(parse_seed, m)?)?;
    m.add_function(wrap_pyfunction!(py_planner::register_planner, m)?)?;
    m.add_function(wrap_pyfunction!(py_planner::unregister_planner, m)?)?;
    m.add_function(wrap_pyfunction!(py_planner::python_planners, m)?)?;
    m.add_class::<env_core::EnvCore>()?;
    m.add_class::<road::Road>()?;
    Ok(())
}

/// Names of the built-in scenarios.
#[pyfunction]
fn builtin_scenarios() -> Vec<&'static str> {
    scenarios::builtin::names()
}

/// Names of the registered planners (the built-in ones and the Python ones), sorted.
#[pyfunction]
fn planners() -> PyResult<Vec<String>> {
    Ok(py_planner::registry()?
        .names()
        .into_iter()
        .map(str::to_string)
        .collect())
}

/// The seed of instance `instance` of a sweep with seed `sweep_seed` (what the sweep ran it with).
#[pyfunction]
fn instance_seed(sweep_seed: u64, instance: u64) -> u64 {
    mergesim::sweep::instance_seed(sweep_seed, instance)
}

/// A seed written as text: `0x` and hex digits (what the result files write) or decimal digits;
/// anything else (a float such as `9.853264649648847e18`) raises `ScenarioError`.
#[pyfunction]
fn parse_seed(text: &str) -> PyResult<u64> {
    mergesim::exact_seed::parse_seed(text).map_err(|e| errors::BindingError::input(&e).into())
}
