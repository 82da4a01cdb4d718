//! Running a study: every (cell, instance, planner) of a shard in parallel, the same instance
//! seeds for every cell and planner (so the differences are paired), one row per run handed to
//! the caller as it finishes (the CLI appends it to the JSONL); resumable from those rows.
//!
//! Sharding and seeds are the sweep's: instance i runs with
//! [`crate::sweep::instance_seed`]`(K, i)` and shard `i/n` runs the instance
//! block [`Shard::instances`] of every cell and planner. The rows are sorted by (cell, planner,
//! instance) before any figure is computed from them, so the report does not depend on the
//! thread count, the scheduling, the sharding or the resumption.

use std::collections::BTreeMap;
use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::plan::StudyPlan;
use crate::experiment::{InstanceOptions, RunError, run_instance};
use crate::sweep::{RunStatus, Shard, instance_seed};

/// An endpoint's values in one run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EndpointValues {
    /// Over the window before the run's first contact (the whole run without contact); null
    /// where the run's figure is null.
    pub pre_contact: Option<f64>,
    /// Over the whole run.
    pub whole_run: Option<f64>,
}

/// One run of a study: one planner on one instance of one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyRow {
    /// Cell index (the plan's order).
    pub cell: usize,
    /// Instance index.
    pub instance: u64,
    /// Planner name.
    pub planner: String,
    /// The instance's seed (a string in JSON): `merge_sim run --seed` replays it on the cell's
    /// scenario.
    #[serde(with = "crate::exact_seed")]
    pub seed: u64,
    /// How it ended.
    pub status: RunStatus,
    /// The error of a run that did not complete.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Whether the run had a contact (vehicle–vehicle or road edge).
    pub collided: bool,
    /// Contact events of the run.
    pub collisions: u64,
    /// Time of the first contact (s); null without one.
    pub first_contact_t_s: Option<f64>,
    /// Each endpoint's values, by its name in the plan.
    pub endpoints: BTreeMap<String, EndpointValues>,
}

/// A JSONL line: the row with its plan's identity and wall time.
#[derive(Serialize, Deserialize)]
struct Line {
    study: String,
    plan_fingerprint: String,
    #[serde(flatten)]
    row: StudyRow,
    #[serde(default)]
    wall_time_s: Option<f64>,
}

/// Why a study could not run or its rows be read.
#[derive(Debug, Error)]
pub enum StudyError {
    /// Bad input: rows of another plan or shard, a torn file, duplicates (exit code 2).
    #[error("{0}")]
    Invalid(String),
    /// The worker pool could not start, or an output failed (exit code 1).
    #[error("{0}")]
    Run(String),
}

/// How to run a study (does not change its results).
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The planners by name ([`sim::registry::BehaviourRegistry::builtin`] by default; the registry the
    /// plan was checked against).
    pub registry: Arc<sim::registry::BehaviourRegistry>,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// The part to run.
    pub shard: Option<Shard>,
    /// Once set, no run starts and running ones stop.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Rows of an earlier attempt (`--resume`): not run again.
    pub resume: Vec<StudyRow>,
}

impl Default for RunOptions {
    /// The built-in planners, one thread per core, the whole study, nothing resumed.
    fn default() -> Self {
        Self {
            registry: Arc::new(sim::registry::BehaviourRegistry::builtin()),
            threads: None,
            shard: None,
            interrupt: None,
            resume: Vec::new(),
        }
    }
}

/// The (cell, instance, planner) keys of the runs of `shard`, in (cell, planner, instance)
/// order.
pub fn run_keys(plan: &StudyPlan, shard: Shard) -> Vec<(usize, u64, String)> {
    let range = shard.instances(plan.instances);
    let mut keys = Vec::new();
    for (cell, _) in &plan.cells {
        for planner in &plan.planners {
            for instance in range.clone() {
                keys.push((cell.index, instance, planner.clone()));
            }
        }
    }
    keys
}

/// Runs one (cell, instance, planner) of the plan with the planners of `registry`.
pub fn run_one(
    plan: &StudyPlan,
    cell: usize,
    instance: u64,
    planner: &str,
    registry: &sim::registry::BehaviourRegistry,
    interrupt: Option<Arc<AtomicBool>>,
) -> Option<StudyRow> {
    let seed = instance_seed(plan.seed, instance);
    let scenario = &plan.cells[cell].1;
    let options = InstanceOptions {
        planner: Some(planner.to_string()),
        seed: Some(seed),
        keep_time_series: false,
        interrupt,
        profile: false,
    };
    let result = catch_unwind(AssertUnwindSafe(|| {
        run_instance(
            scenario,
            &options,
            sim::recording::Recorder::disabled(),
            registry,
            |_| {},
        )
    }));
    let mut row = StudyRow {
        cell,
        instance,
        planner: planner.to_string(),
        seed,
        status: RunStatus::Completed,
        error: None,
        collided: false,
        collisions: 0,
        first_contact_t_s: None,
        endpoints: BTreeMap::new(),
    };
    match result {
        Ok(Ok(finished)) => {
            let summary = &finished.summary;
            let safety = &finished.outcome.safety;
            row.collisions = summary.collisions as u64;
            row.collided = summary.collisions > 0;
            // The simulated vehicles' own contacts: not those caused by recorded traffic.
            row.first_contact_t_s = safety
                .collisions
                .iter()
                .filter(|c| !c.caused_by_replay)
                .map(|c| c.t_s)
                .chain(safety.edge_contacts.iter().map(|e| e.t_s))
                .reduce(f64::min);
            for endpoint in plan.endpoints() {
                let (pre_contact, whole_run) = endpoint.figure.values(summary);
                row.endpoints.insert(
                    endpoint.figure.name.clone(),
                    EndpointValues {
                        pre_contact,
                        whole_run,
                    },
                );
            }
        }
        Ok(Err(RunError::Run(sim::SimError::Interrupted { .. }))) => return None,
        Ok(Err(e)) => {
            row.status = RunStatus::Diverged;
            row.error = Some(e.to_string());
        }
        Err(_) => {
            row.status = RunStatus::Panicked;
            row.error = Some("panic while simulating".into());
        }
    }
    Some(row)
}

/// Runs the shard's missing runs in parallel; `on_run` gets each row and its wall time as it
/// finishes (from the worker threads). Returns every row of the shard (resumed and new) in
/// (cell, planner, instance) order; fewer than [`run_keys`] when interrupted.
pub fn run_study(
    plan: &StudyPlan,
    options: &RunOptions,
    on_run: &(dyn Fn(&StudyRow, f64) + Sync),
) -> Result<Vec<StudyRow>, StudyError> {
    let shard = options.shard.unwrap_or(Shard::WHOLE);
    let keys = run_keys(plan, shard);
    let wanted: BTreeSet<(usize, u64, &str)> =
        keys.iter().map(|(c, i, p)| (*c, *i, p.as_str())).collect();
    let mut done = BTreeSet::new();
    for row in &options.resume {
        let key = (row.cell, row.instance, row.planner.as_str());
        if !wanted.contains(&key) {
            return Err(StudyError::Invalid(format!(
                "resumed row of cell {} instance {} ({}) is not a run of shard {shard}",
                row.cell, row.instance, row.planner
            )));
        }
        if !done.insert(key) {
            return Err(StudyError::Invalid(format!(
                "cell {} instance {} ({}) appears twice among the resumed rows",
                row.cell, row.instance, row.planner
            )));
        }
    }
    let todo: Vec<&(usize, u64, String)> = keys
        .iter()
        .filter(|(c, i, p)| !done.contains(&(*c, *i, p.as_str())))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.unwrap_or(0))
        .stack_size(16 << 20)
        .build()
        .map_err(|e| StudyError::Run(format!("cannot start the worker threads: {e}")))?;
    let interrupted = || {
        options
            .interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    };
    let new_rows: Vec<StudyRow> = pool.install(|| {
        todo.into_par_iter()
            .filter_map(|(cell, instance, planner)| {
                if interrupted() {
                    return None;
                }
                let started = std::time::Instant::now();
                let row = run_one(
                    plan,
                    *cell,
                    *instance,
                    planner,
                    &options.registry,
                    options.interrupt.clone(),
                )?;
                on_run(&row, started.elapsed().as_secs_f64());
                Some(row)
            })
            .collect()
    });
    let mut rows: Vec<StudyRow> = options.resume.iter().cloned().chain(new_rows).collect();
    sort_rows(plan, &mut rows);
    Ok(rows)
}

/// Sorts rows by (cell, planner in the plan's order, instance).
pub fn sort_rows(plan: &StudyPlan, rows: &mut [StudyRow]) {
    let order = |name: &str| {
        plan.planners
            .iter()
            .position(|p| p == name)
            .unwrap_or(usize::MAX)
    };
    rows.sort_by(|a, b| {
        (a.cell, order(&a.planner), a.instance).cmp(&(b.cell, order(&b.planner), b.instance))
    });
}

/// The JSONL line of a row (no newline).
pub fn jsonl_line(plan: &StudyPlan, row: &StudyRow, wall_time_s: Option<f64>) -> String {
    let line = Line {
        study: plan.name.clone(),
        plan_fingerprint: plan.fingerprint(),
        row: row.clone(),
        wall_time_s,
    };
    // A row holds only strings, numbers and maps of them: it always serialises.
    serde_json::to_string(&line).unwrap_or_default()
}

/// The rows of a JSONL text written for `plan` (`origin` names it in errors): every complete
/// line must be a row of this plan (same fingerprint) and a run of the plan; a last line cut
/// short by a kill is dropped (returned `torn` = true). Returns (rows, complete length, torn).
pub fn read_rows(
    plan: &StudyPlan,
    text: &str,
    origin: &str,
) -> Result<(Vec<StudyRow>, usize, bool), StudyError> {
    let complete_len = text.rfind('\n').map_or(0, |i| i + 1);
    let fingerprint = plan.fingerprint();
    let mut rows = Vec::new();
    for (index, line) in text[..complete_len].lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let number = index + 1;
        let parsed: Line = serde_json::from_str(line).map_err(|e| {
            StudyError::Invalid(format!(
                "{origin}, line {number}: not a row of `merge_sim study`: {e}"
            ))
        })?;
        if parsed.plan_fingerprint != fingerprint {
            return Err(StudyError::Invalid(format!(
                "{origin}, line {number}: plan_fingerprint = {}, but the plan's is {fingerprint}: \
                 the rows were written for another version of the plan (rerun without --resume)",
                parsed.plan_fingerprint
            )));
        }
        let row = parsed.row;
        if row.cell >= plan.cells.len()
            || row.instance >= plan.instances
            || !plan.planners.contains(&row.planner)
            || row.seed != instance_seed(plan.seed, row.instance)
        {
            return Err(StudyError::Invalid(format!(
                "{origin}, line {number}: cell {} instance {} ({}, seed {}) is not a run of this \
                 plan",
                row.cell, row.instance, row.planner, row.seed
            )));
        }
        rows.push(row);
    }
    Ok((rows, complete_len, complete_len < text.len()))
}

/// Checks that `rows` hold every run of the plan exactly once (after a merge of shards).
pub fn check_complete(plan: &StudyPlan, rows: &[StudyRow]) -> Result<(), StudyError> {
    let mut seen = BTreeSet::new();
    for row in rows {
        if !seen.insert((row.cell, row.instance, row.planner.clone())) {
            return Err(StudyError::Invalid(format!(
                "cell {} instance {} ({}) appears twice",
                row.cell, row.instance, row.planner
            )));
        }
    }
    let missing: Vec<String> = run_keys(plan, Shard::WHOLE)
        .into_iter()
        .filter(|k| !seen.contains(k))
        .take(5)
        .map(|(c, i, p)| format!("cell {c} instance {i} ({p})"))
        .collect();
    if !missing.is_empty() {
        return Err(StudyError::Invalid(format!(
            "{} of {} runs missing (e.g. {}): run or resume the missing shards",
            plan.total_runs() as usize - seen.len(),
            plan.total_runs(),
            missing.join(", ")
        )));
    }
    Ok(())
}
