//! `mergesim.run`: one run of a scenario, as `merge_sim run --json --csv` makes it.

use mergesim::experiment::{InstanceOptions, RunError, run_instance};
use mergesim::report::time_series_csv;
use pyo3::prelude::*;

use crate::background::run_interruptible;
use crate::errors::BindingError;
use crate::source;

/// Runs one instance; returns the JSON summary (`merge_sim run --json`) and the time series as
/// CSV text (`merge_sim run --csv`). The simulation runs without the GIL, on a pool of its own,
/// and stops on Ctrl-C (`background`).
#[pyfunction]
#[pyo3(signature = (scenario, params_json = None, planner = None, seed = None))]
pub(crate) fn run(
    py: Python<'_>,
    scenario: &str,
    params_json: Option<&str>,
    planner: Option<&str>,
    seed: Option<u64>,
) -> PyResult<(String, String)> {
    let scenario = source::load(scenario, params_json)?;
    // The built-in planners and the Python ones registered now; the name checked as
    // `merge_sim run --planner` checks it (the same message).
    let registry = crate::py_planner::registry()?;
    if let Some(name) = planner
        && !registry.contains(name)
    {
        return Err(
            BindingError::Input(mergesim::experiment::unknown_planner(&registry, name)).into(),
        );
    }
    // The scenario's planners, their tables and vehicle models, with the file's line, as
    // `merge_sim run` checks them.
    scenario
        .check_planners(&registry)
        .map_err(|e| BindingError::input(&e))?;
    let planner = planner.map(str::to_string);
    let finished = run_interruptible(py, None, |interrupt| {
        let options = InstanceOptions {
            planner,
            seed,
            keep_time_series: true,
            interrupt: Some(interrupt),
            profile: false,
        };
        run_instance(
            &scenario,
            &options,
            sim::recording::Recorder::disabled(),
            &registry,
            |_| {},
        )
    })?
    .map_err(|e| match e {
        RunError::Setup(e) => BindingError::input(&e),
        RunError::Run(e) => BindingError::run(&e),
    })?;
    let summary = finished.summary.with_drawn(&scenario);
    let summary = serde_json::to_string(&summary)
        .map_err(|e| BindingError::Run(format!("cannot encode the summary: {e}")))?;
    Ok((summary, time_series_csv(&finished.outcome.time_series)))
}
