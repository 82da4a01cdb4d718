//! One library entry for running a scenario: what `merge_sim run`, `compare`, `sweep` and `grid`,
//! the integration tests and the benchmarks all call, so a run means the same thing everywhere.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use scenarios::scenario::Scenario;
use sim::recording::Recorder;
use sim::registry::BehaviourRegistry;
use sim::{RunOptions, RunOutcome, SimError, World};
use thiserror::Error;

use crate::summary::RunSummary;

/// How to run one instance of a scenario.
#[derive(Clone, Debug, Default)]
pub struct InstanceOptions {
    /// A registered planner name that replaces every `driver = { planner = … }`.
    pub planner: Option<String>,
    /// `None`: the nominal scenario; `Some(seed)`: the instance drawn with that seed from its
    /// `[randomise]` ranges (as a sweep runs it; the seed also seeds the V2V drops).
    pub seed: Option<u64>,
    /// Keep the time series (`--csv`, figures).
    pub keep_time_series: bool,
    /// Stop the run (with [`sim::SimError::Interrupted`]) once this flag is set, e.g. by a
    /// SIGINT/SIGTERM handler.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Time each phase of the tick (`RunSummary::profile`).
    pub profile: bool,
}

/// Why a run did not finish.
#[derive(Debug, Error)]
pub enum RunError {
    /// The world could not be built from the scenario (bad input: exit code 2).
    #[error(transparent)]
    Setup(SimError),
    /// The simulation failed while running (exit code 1).
    #[error(transparent)]
    Run(SimError),
}

/// A finished run: its JSON summary and the full outcome.
#[derive(Clone, Debug)]
pub struct Finished {
    /// What `--json` writes.
    pub summary: RunSummary,
    /// Everything the world measured (time series if asked for).
    pub outcome: RunOutcome,
}

/// The message for a planner name `registry` does not hold (the same from the CLI, the library
/// and Python): `unknown planner 'NAME'; valid: A, B, …`.
pub fn unknown_planner(registry: &BehaviourRegistry, name: &str) -> String {
    format!(
        "unknown planner '{name}'; valid: {}",
        registry.names().join(", ")
    )
}

/// The planner label of a run: the override, or the scenario's single planner, or `mixed`
/// (`none` without any planner-driven vehicle).
pub fn planner_label(scenario: &Scenario, planner: Option<&str>) -> String {
    if let Some(name) = planner {
        return name.to_string();
    }
    let mut names: Vec<&str> = scenario
        .vehicles
        .iter()
        .filter_map(|v| match &v.driver {
            sim::config::Driver::Planner { name, .. } => Some(name.as_str()),
            _ => None,
        })
        .collect();
    names.sort_unstable();
    names.dedup();
    match names.as_slice() {
        [] => "none".into(),
        [one] => (*one).to_string(),
        _ => "mixed".into(),
    }
}

/// Runs one instance of `scenario` with the planners of `registry`, writing into `recorder`
/// (`Recorder::disabled()` for none) and calling `progress(fraction)` about a hundred times.
pub fn run_instance(
    scenario: &Scenario,
    options: &InstanceOptions,
    recorder: Recorder,
    registry: &BehaviourRegistry,
    progress: impl FnMut(f64),
) -> Result<Finished, RunError> {
    let instance = scenario.instance(options.seed);
    let run_options = RunOptions {
        planner_override: options.planner.clone(),
        seed: options.seed.unwrap_or(0),
        keep_time_series: options.keep_time_series,
        profile: options.profile,
    };
    let world = World::with_registry(
        instance.sim,
        &instance.vehicles,
        &run_options,
        recorder,
        registry,
    )
    .map_err(RunError::Setup)?;
    let started = Instant::now();
    let interrupt = options.interrupt.clone();
    let outcome = world
        .run_until(progress, || {
            interrupt
                .as_ref()
                .is_some_and(|flag| flag.load(Ordering::Relaxed))
        })
        .map_err(RunError::Run)?;
    let wall_time_s = started.elapsed().as_secs_f64();
    let label = planner_label(scenario, options.planner.as_deref());
    let summary = RunSummary::new(
        &scenario.name,
        scenario.params,
        &label,
        options.seed,
        wall_time_s,
        &outcome,
    )
    .with_recorded_traffic(&scenario.sim)
    .with_vehicle_model(&scenario.sim, &scenario.vehicles);
    Ok(Finished { summary, outcome })
}

/// [`run_instance`] with the built-in planners, no recording and no progress.
pub fn run_quietly(scenario: &Scenario, options: &InstanceOptions) -> Result<Finished, RunError> {
    run_instance(
        scenario,
        options,
        Recorder::disabled(),
        &BehaviourRegistry::builtin(),
        |_| {},
    )
}
