//! `mergesim.study`: runs a study plan (`merge_sim study PLAN.toml`: the library's
//! `mergesim::study`) and returns its report (`report.json`) as JSON text, which
//! `mergesim/study.py` turns into DataFrames.

use std::path::Path;

use mergesim::study::plan::StudyPlan;
use mergesim::study::run_and_report;
use mergesim::study::runner::{RunOptions, StudyError};
use pyo3::prelude::*;

use crate::background::run_interruptible;
use crate::errors::BindingError;

/// Runs every run of the plan at `plan` (a path; relative paths in it start from its folder)
/// without the GIL, stopping on Ctrl-C, and returns the report as JSON; with `out`, also writes
/// the report folder as `merge_sim study --out` does. A bad plan raises `ScenarioError` with the
/// CLI's message (file, line, field).
#[pyfunction]
#[pyo3(signature = (plan, out = None, threads = None))]
pub(crate) fn study(
    py: Python<'_>,
    plan: &str,
    out: Option<&str>,
    threads: Option<usize>,
) -> PyResult<String> {
    // The built-in planners and the Python ones registered now.
    let registry = std::sync::Arc::new(crate::py_planner::registry()?);
    let plan =
        StudyPlan::load_with(Path::new(plan), &registry).map_err(|e| BindingError::input(&e))?;
    let report = run_interruptible(py, Some(1), |interrupt| {
        let options = RunOptions {
            threads,
            interrupt: Some(interrupt),
            registry,
            ..RunOptions::default()
        };
        run_and_report(&plan, &options, out.map(Path::new))
    })?
    .map_err(|e| match e {
        StudyError::Invalid(_) => BindingError::input(&e),
        StudyError::Run(_) => BindingError::run(&e),
    })?;
    serde_json::to_string(&report)
        .map_err(|e| BindingError::Run(format!("cannot encode the report: {e}")).into())
}
