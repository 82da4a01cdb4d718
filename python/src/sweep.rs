//! `mergesim.sweep`: a seeded Monte-Carlo sweep of one or several planners over the same
//! instances (paired by seed), run in parallel by the library (`mergesim::sweep`'s paired sweep,
//! what `merge_sim sweep --planners` runs).

use mergesim::sweep::{
    PairedSweepPlan, Shard, SweepError, SweepIdentity, SweepOptions, jsonl_line, run_paired_sweep,
};
use pyo3::prelude::*;

use crate::background::run_interruptible;
use crate::errors::BindingError;
use crate::source;

/// Sweeps `runs` instances drawn with sweep seed `seed` for every planner of `planners` (empty:
/// the scenario's own); returns the JSONL rows (`merge_sim sweep --jsonl`) in instance order,
/// the planners of an instance in the given order. Instance `i` has the same seed, so the same
/// drawn scenario, for every planner. The sweep runs without the GIL and stops on Ctrl-C
/// (`background`).
#[pyfunction]
#[pyo3(signature = (scenario, planners, runs, seed, params_json = None, threads = None))]
pub(crate) fn sweep(
    py: Python<'_>,
    scenario: &str,
    planners: Vec<String>,
    runs: u64,
    seed: u64,
    params_json: Option<&str>,
    threads: Option<usize>,
) -> PyResult<Vec<String>> {
    let scenario = source::load(scenario, params_json)?;
    // The built-in planners and the Python ones registered now.
    let registry = std::sync::Arc::new(crate::py_planner::registry()?);
    // The scenario's planners, their tables and vehicle models, with the file's line, as
    // `merge_sim sweep` checks them.
    scenario
        .check_planners(&registry)
        .map_err(|e| BindingError::input(&e))?;
    let plan = PairedSweepPlan {
        scenario,
        planners,
        runs,
        seed,
        shard: Shard::WHOLE,
    };
    let outcome = run_interruptible(py, Some(1), |interrupt| {
        // The sweep builds its own pool of `threads` workers (one per core by default).
        let options = SweepOptions {
            threads,
            interrupt: Some(interrupt),
            registry,
            ..SweepOptions::default()
        };
        run_paired_sweep(&plan, &options, &|_| {})
    })?
    .map_err(|e| match e {
        SweepError::Threads(_) => BindingError::run(&e),
        SweepError::Invalid(_) => BindingError::input(&e),
    })?;
    // The sweep's identity (all its planners), as the CLI writes it on every line.
    let identity = SweepIdentity::of_paired(&plan);
    // (instance, planner index, line), sorted by instance then the plan's planner order.
    let mut lines = Vec::new();
    for (index, (summary, wall_times_s)) in outcome
        .summaries
        .iter()
        .zip(&outcome.run_wall_times_s)
        .enumerate()
    {
        for (row, wall_time_s) in summary.samples.iter().zip(wall_times_s) {
            let line = jsonl_line(&identity, row, *wall_time_s)
                .map_err(|e| BindingError::Run(format!("cannot encode a row: {e}")))?;
            lines.push((row.instance, index, line));
        }
    }
    lines.sort_by_key(|(instance, index, _)| (*instance, *index));
    Ok(lines.into_iter().map(|(_, _, line)| line).collect())
}
