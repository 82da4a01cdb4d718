//! `mergesim.sweep`: seeded Monte-Carlo sweeps of one or several planners over the same
//! instances (paired by seed), run in parallel by the library's sweep (`mergesim::sweep`).

use mergesim::sweep::{Shard, SweepIdentity, SweepOptions, SweepPlan, jsonl_line, run_sweep};
use planner::PlannerKind;
use pyo3::prelude::*;

use crate::errors::BindingError;
use crate::source;

/// Sweeps `runs` instances drawn with sweep seed `seed` for every planner of `planners` (`None`:
/// the scenario's own); returns the JSONL rows (`merge_sim sweep --jsonl`), planner after
/// planner, each in instance order. Instance `i` has the same seed, so the same drawn scenario,
/// for every planner. The GIL is released while the sweeps run.
#[pyfunction]
#[pyo3(signature = (scenario, planners, runs, seed, params_json = None, threads = None))]
pub fn sweep(
    py: Python<'_>,
    scenario: &str,
    planners: Vec<Option<String>>,
    runs: u64,
    seed: u64,
    params_json: Option<&str>,
    threads: Option<usize>,
) -> PyResult<Vec<String>> {
    let scenario = source::load(scenario, params_json)?;
    if planners.is_empty() {
        return Err(BindingError::Input("planners: give at least one planner".into()).into());
    }
    let kinds = planners
        .iter()
        .map(|name| {
            name.as_deref()
                .map(|n| n.parse::<PlannerKind>())
                .transpose()
                .map_err(|e| BindingError::input(&e))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let options = SweepOptions {
        threads,
        ..SweepOptions::default()
    };
    let lines = py.detach(|| -> Result<Vec<String>, BindingError> {
        let mut lines = Vec::new();
        for planner in kinds {
            let plan = SweepPlan {
                scenario: scenario.clone(),
                planner,
                runs,
                seed,
                shard: Shard::WHOLE,
            };
            let outcome = run_sweep(&plan, &options, &|_| {}).map_err(|e| match e {
                mergesim::sweep::SweepError::Invalid(_) => BindingError::input(&e),
                mergesim::sweep::SweepError::Threads(_) => BindingError::run(&e),
            })?;
            let identity = SweepIdentity::of(&plan);
            for (row, wall_time_s) in outcome
                .summary
                .samples
                .iter()
                .zip(&outcome.run_wall_times_s)
            {
                lines.push(
                    jsonl_line(&identity, row, *wall_time_s)
                        .map_err(|e| BindingError::Run(format!("cannot encode a row: {e}")))?,
                );
            }
        }
        Ok(lines)
    })?;
    Ok(lines)
}
