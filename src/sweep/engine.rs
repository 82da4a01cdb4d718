//! The sweep engine: every (instance, planner) of a shard run in parallel, the rows collected in
//! (instance, planner) order whatever the scheduling, and reduced per planner.

use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::Ordering;
use std::time::Instant;

use rayon::prelude::*;

use super::{
    FinishedRun, MAX_RUNS, MAX_THREADS, PairedSweepOutcome, PairedSweepPlan, RunFailure,
    RunFigures, RunRow, RunStatus, SweepError, SweepIdentity, SweepOptions, SweepSummary,
    drawn_values, instance_seed,
};

/// One run a sweep asks its runner for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunRequest {
    /// Instance index.
    pub instance: u64,
    /// The instance's seed ([`instance_seed`]).
    pub seed: u64,
    /// The planner override, a registered name (`None`: the scenario's own planners).
    pub planner: Option<String>,
}

/// Checks a multi-planner plan and its options before any work: the run and thread counts,
/// every planner registered in the options' registry (the plan's and the scenario's own), no
/// planner listed twice, and that every resumed row belongs to the sweep (its shard, its seed,
/// one of its planners) and appears once per (instance, planner).
pub fn validate_paired(plan: &PairedSweepPlan, options: &SweepOptions) -> Result<(), SweepError> {
    if plan.runs == 0 || plan.runs > MAX_RUNS {
        return Err(SweepError::Invalid(format!(
            "runs = {}: a sweep runs 1 to {MAX_RUNS} instances (for more, run several sweeps \
             with different seeds)",
            plan.runs
        )));
    }
    if let Some(threads) = options.threads
        && !(1..=MAX_THREADS).contains(&threads)
    {
        return Err(SweepError::Invalid(format!(
            "threads = {threads}: need 1 to {MAX_THREADS}"
        )));
    }
    check_planner_names(plan, &options.registry)?;
    let labels = plan.labels();
    for (i, label) in labels.iter().enumerate() {
        if labels[..i].contains(label) {
            return Err(SweepError::Invalid(format!(
                "planners: {label} is listed twice (each planner runs once per instance)"
            )));
        }
    }
    let range = plan.shard.instances(plan.runs);
    let mut seen = BTreeSet::new();
    for run in &options.resume {
        let row = &run.row;
        if !range.contains(&row.instance) {
            return Err(SweepError::Invalid(format!(
                "resumed row of instance {} lies outside shard {}'s instances {}..{}",
                row.instance, plan.shard, range.start, range.end
            )));
        }
        let expected = instance_seed(plan.seed, row.instance);
        if row.seed != expected {
            return Err(SweepError::Invalid(format!(
                "resumed row of instance {} has seed {}, not {expected} = the seed of instance \
                 {} of a sweep with seed {}: not a row of this sweep",
                row.instance, row.seed, row.instance, plan.seed
            )));
        }
        if !labels.contains(&row.planner) {
            return Err(SweepError::Invalid(format!(
                "resumed row of instance {} has planner {}, not one of this sweep's ({}): not a \
                 row of this sweep",
                row.instance,
                row.planner,
                labels.join(", ")
            )));
        }
        if !seen.insert((row.instance, row.planner.clone())) {
            return Err(SweepError::Invalid(format!(
                "instance {} ({}) appears twice among the resumed rows",
                row.instance, row.planner
            )));
        }
    }
    Ok(())
}

/// [`run_paired_sweep`](super::run_paired_sweep) with any runner (request → figures or
/// failure), e.g. a fake one in tests. The drawn values of each row come from the plan's
/// scenario, not from the runner.
pub fn run_paired_sweep_with<F>(
    plan: &PairedSweepPlan,
    options: &SweepOptions,
    on_run: &(dyn Fn(&FinishedRun) + Sync),
    runner: F,
) -> Result<PairedSweepOutcome, SweepError>
where
    F: Fn(&RunRequest) -> Result<RunFigures, RunFailure> + Sync,
{
    validate_paired(plan, options)?;
    let identity = SweepIdentity::of_paired(plan);
    let labels = plan.labels();
    let overrides = plan.overrides();
    let range = plan.shard.instances(plan.runs);
    let done: BTreeSet<(u64, &str)> = options
        .resume
        .iter()
        .map(|r| (r.row.instance, r.row.planner.as_str()))
        .collect();
    // Instance-major: the planners of an instance run close together.
    let todo: Vec<(u64, usize)> = range
        .clone()
        .flat_map(|i| (0..labels.len()).map(move |p| (i, p)))
        .filter(|&(i, p)| !done.contains(&(i, labels[p].as_str())))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.unwrap_or(0))
        // A World keeps sizeable locals on the stack; give the workers the main thread's 8 MiB
        // and some margin rather than the 2 MiB default of spawned threads.
        .stack_size(16 << 20)
        .build()
        .map_err(|e| SweepError::Threads(e.to_string()))?;
    let interrupted = || {
        options
            .interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    };
    let started = Instant::now();
    let new_runs: Vec<FinishedRun> = pool.install(|| {
        todo.into_par_iter()
            .filter_map(|(instance, p)| {
                if interrupted() {
                    return None;
                }
                let request = RunRequest {
                    instance,
                    seed: instance_seed(plan.seed, instance),
                    planner: overrides[p].clone(),
                };
                let run_started = Instant::now();
                let result = catch_unwind(AssertUnwindSafe(|| runner(&request)));
                let wall_time_s = run_started.elapsed().as_secs_f64();
                let (status, error, figures) = match result {
                    Ok(Ok(figures)) => (RunStatus::Completed, None, Some(figures)),
                    Ok(Err(RunFailure::Interrupted)) => return None,
                    Ok(Err(RunFailure::Failed(error))) => (RunStatus::Diverged, Some(error), None),
                    Err(payload) => (
                        RunStatus::Panicked,
                        Some(panic_message(payload.as_ref())),
                        None,
                    ),
                };
                let (metrics, vehicles) = match figures {
                    Some(f) => (Some(f.metrics), f.vehicles),
                    None => (None, Vec::new()),
                };
                let run = FinishedRun {
                    row: RunRow {
                        instance,
                        planner: labels[p].clone(),
                        seed: request.seed,
                        status,
                        error,
                        drawn: drawn_values(&plan.scenario, request.seed),
                        metrics,
                        vehicles,
                    },
                    wall_time_s,
                };
                on_run(&run);
                Some(run)
            })
            .collect()
    });
    let wall_time_s = started.elapsed().as_secs_f64();
    let new_count = new_runs.len() as u64;
    let mut per_planner: Vec<Vec<FinishedRun>> = vec![Vec::new(); labels.len()];
    for run in options.resume.iter().cloned().chain(new_runs) {
        if let Some(p) = labels.iter().position(|l| *l == run.row.planner) {
            per_planner[p].push(run);
        }
    }
    let mut summaries = Vec::with_capacity(labels.len());
    let mut run_wall_times_s = Vec::with_capacity(labels.len());
    for (label, mut runs) in labels.iter().zip(per_planner) {
        runs.sort_by_key(|r| r.row.instance);
        let (rows, walls): (Vec<RunRow>, Vec<f64>) =
            runs.into_iter().map(|r| (r.row, r.wall_time_s)).unzip();
        summaries.push(SweepSummary::from_rows(
            &identity.for_planner(label),
            plan.shard,
            rows,
            wall_time_s,
        ));
        run_wall_times_s.push(walls);
    }
    Ok(PairedSweepOutcome {
        interrupted: summaries.iter().any(|s| s.missing_runs > 0),
        summaries,
        run_wall_times_s,
        new_runs: new_count,
        wall_time_s,
    })
}

/// Every planner the plan runs is in `registry`: the plan's list, and the scenario's own
/// `driver = { planner = … }` (and prescribed drivers' `path_planner`) where the list does not
/// replace them.
fn check_planner_names(
    plan: &PairedSweepPlan,
    registry: &sim::registry::BehaviourRegistry,
) -> Result<(), SweepError> {
    let unknown = |name: &str, whose: &str| {
        SweepError::Invalid(format!(
            "{whose}: {}",
            crate::experiment::unknown_planner(registry, name)
        ))
    };
    for name in &plan.planners {
        if !registry.contains(name) {
            return Err(SweepError::Invalid(crate::experiment::unknown_planner(
                registry, name,
            )));
        }
    }
    for vehicle in &plan.scenario.vehicles {
        match &vehicle.driver {
            sim::config::Driver::Planner { name, .. }
                if plan.planners.is_empty() && !registry.contains(name) =>
            {
                return Err(unknown(name, &format!("vehicle {}", vehicle.name)));
            }
            sim::config::Driver::Prescribed { path_planner, .. }
                if !registry.contains(path_planner) =>
            {
                return Err(unknown(path_planner, &format!("vehicle {}", vehicle.name)));
            }
            _ => {}
        }
    }
    Ok(())
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown payload".into());
    format!("panic: {text}")
}
