//! The sensitivity grid (`merge_sim grid`): how the comparison of the planners depends on the
//! four path-generation and interaction choices that shape it.
//!
//! Axes (each cell applies them on top of the scenario's parameter set):
//! - `predict_obstacles_in_path`: the others at their constant-velocity positions in Eq. 7, or
//!   at their current positions (the paper's reading);
//! - sub-steps: the Eq. 7 step integrated in adaptive sub-steps of at most 1 m
//!   (`max_substep_m` = 1, `substep_max_turn_rad` = 0.1) or in one gradient step per waypoint
//!   (the paper's);
//! - the path field's time gap τ (`obstacle_time_gap_s`): 0 (the paper's D_min), 1, 2 (the
//!   `mergesim` set's), 3 s;
//! - the interaction term's time gap τ_I (`interaction_time_gap_s`): 1, 2, 3 s.
//!
//! Every cell runs every planner on the same instances (the nominal scenario, or `runs` drawn
//! instances with the seeds a sweep uses), so the differences between planners are paired.
//! Planners without the interaction term (PF-CS, PF-SP, PF-SP-EQ10) do not depend on τ_I: they
//! run once per (prediction, sub-steps, τ) and their rows are shared by the τ_I cells — the
//! separation of the two parameter families makes that exact (tested).

use std::time::Instant;

use planner::PlannerKind;
use planner::params::PlannerParams;
use rayon::prelude::*;
use scenarios::scenario::Scenario;
use serde::{Deserialize, Serialize};
use sim::registry::BehaviourRegistry;

use crate::experiment::{InstanceOptions, run_instance};

use crate::sweep::instance_seed;

mod paired;

pub use paired::{GridMetric, PairedDifference};

/// One cell of the grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridCell {
    /// Obstacles at their predicted positions in Eq. 7.
    pub predict_obstacles_in_path: bool,
    /// Adaptive 1 m sub-steps in Eq. 7 (false: one gradient step per waypoint).
    pub substeps: bool,
    /// τ of the path field (s).
    pub path_time_gap_s: f64,
    /// τ_I of the interaction term (s).
    pub interaction_time_gap_s: f64,
}

impl GridCell {
    /// The parameters of this cell on top of `base`.
    pub fn apply(&self, base: &PlannerParams) -> PlannerParams {
        let (max_substep_m, substep_max_turn_rad) = if self.substeps {
            (1.0, 0.1)
        } else {
            (1000.0, 0.0)
        };
        PlannerParams {
            predict_obstacles_in_path: self.predict_obstacles_in_path,
            max_substep_m,
            substep_max_turn_rad,
            obstacle_time_gap_s: self.path_time_gap_s,
            interaction_time_gap_s: self.interaction_time_gap_s,
            ..base.clone()
        }
    }

    /// A short label, e.g. `pred+sub τ3 τI2`.
    pub fn label(&self) -> String {
        format!(
            "{}{} τ{} τI{}",
            if self.predict_obstacles_in_path {
                "pred"
            } else {
                "now"
            },
            if self.substeps { "+sub" } else { "" },
            self.path_time_gap_s,
            self.interaction_time_gap_s
        )
    }
}

/// The values of each axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridAxes {
    /// `predict_obstacles_in_path` values.
    pub predict_obstacles_in_path: Vec<bool>,
    /// Sub-step values.
    pub substeps: Vec<bool>,
    /// τ values (s).
    pub path_time_gap_s: Vec<f64>,
    /// τ_I values (s).
    pub interaction_time_gap_s: Vec<f64>,
}

impl GridAxes {
    /// The single cell of `params`' own values (a paired study of the planners as configured).
    pub fn of_params(params: &PlannerParams) -> Self {
        Self {
            predict_obstacles_in_path: vec![params.predict_obstacles_in_path],
            substeps: vec![params.max_substep_m <= 1.0 && params.substep_max_turn_rad > 0.0],
            path_time_gap_s: vec![params.obstacle_time_gap_s],
            interaction_time_gap_s: vec![params.interaction_time_gap_s],
        }
    }
}

impl Default for GridAxes {
    fn default() -> Self {
        Self {
            predict_obstacles_in_path: vec![false, true],
            substeps: vec![false, true],
            path_time_gap_s: vec![0.0, 1.0, 2.0, 3.0],
            interaction_time_gap_s: vec![1.0, 2.0, 3.0],
        }
    }
}

impl GridAxes {
    /// Every cell, prediction slowest-varying, τ_I fastest.
    pub fn cells(&self) -> Vec<GridCell> {
        let mut cells = Vec::new();
        for &predict_obstacles_in_path in &self.predict_obstacles_in_path {
            for &substeps in &self.substeps {
                for &path_time_gap_s in &self.path_time_gap_s {
                    for &interaction_time_gap_s in &self.interaction_time_gap_s {
                        cells.push(GridCell {
                            predict_obstacles_in_path,
                            substeps,
                            path_time_gap_s,
                            interaction_time_gap_s,
                        });
                    }
                }
            }
        }
        cells
    }
}

/// What the grid measures of one vehicle in one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleFigures {
    /// Vehicle name.
    pub vehicle: String,
    /// Peak |yaw rate| (rad/s).
    pub peak_yaw_rate_radps: f64,
    /// Yaw-rate RMS inside the merge zone (rad/s).
    pub merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// Yaw-rate RMS outside it (rad/s).
    pub outside_merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// Peak |sideslip| (rad).
    pub peak_sideslip_rad: f64,
    /// Lowest speed (m/s).
    pub min_speed_mps: f64,
    /// First time 0.1 m/s below its target (s); null if it never slowed (see
    /// `slowing_onset_never`) or the run kept no paper figures.
    pub slowing_onset_s: Option<f64>,
    /// Whether it never slowed 0.1 m/s below its target (`slowing_onset_s` null means +∞, the
    /// latest onset); null when the run kept no paper figures (not measured).
    #[serde(default)]
    pub slowing_onset_never: Option<bool>,
    /// Path length (m).
    pub path_length_m: f64,
    /// Involved in a collision.
    pub collided: bool,
}

/// One run of the grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridRow {
    /// The cell.
    pub cell: GridCell,
    /// Planner.
    pub planner: String,
    /// Instance index (0 for the nominal scenario).
    pub instance: u64,
    /// Seed of the instance (a `0x` hex string in JSON and CSV); null for the nominal scenario.
    #[serde(with = "crate::exact_seed::option")]
    pub seed: Option<u64>,
    /// Collision episodes (vehicle–vehicle and road edge); null if the run failed.
    pub collisions: Option<u64>,
    /// Why the run failed, if it did.
    pub error: Option<String>,
    /// Per-vehicle figures (empty if the run failed).
    pub vehicles: Vec<VehicleFigures>,
}

/// Most instances a grid cell may run (the default grid runs 36 cells × planners of them).
pub const MAX_GRID_RUNS: u64 = 10_000;

/// What to run.
#[derive(Clone, Debug)]
pub struct GridPlan {
    /// The scenario (its parameter set is the base of every cell).
    pub scenario: Scenario,
    /// Planners by registered name, the first being the reference of the paired differences.
    pub planners: Vec<String>,
    /// The registry the names are looked up in (a user's planners among the built-ins).
    pub registry: std::sync::Arc<BehaviourRegistry>,
    /// The axes.
    pub axes: GridAxes,
    /// 0: the nominal scenario only; else this many drawn instances.
    pub runs: u64,
    /// Sweep seed of the drawn instances.
    pub seed: u64,
    /// Worker threads (None: one per core).
    pub threads: Option<usize>,
    /// Once set (e.g. by a signal handler), no run starts and running ones stop; `run_grid`
    /// then returns an error instead of a partial grid.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Runs of one (cell, planner) job.
struct Job<'a> {
    cell: GridCell,
    planner: &'a str,
    instance: u64,
    seed: Option<u64>,
}

fn figures(outcome: &sim::RunOutcome) -> Vec<VehicleFigures> {
    outcome
        .vehicles
        .iter()
        .map(|v| {
            let paper = v.paper_metrics.as_ref();
            VehicleFigures {
                vehicle: v.id.clone(),
                peak_yaw_rate_radps: v.max_abs_yaw_rate_radps,
                merge_zone_rms_yaw_rate_radps: paper.and_then(|p| p.merge_zone_rms_yaw_rate_radps),
                outside_merge_zone_rms_yaw_rate_radps: paper
                    .and_then(|p| p.outside_merge_zone_rms_yaw_rate_radps),
                peak_sideslip_rad: v.max_abs_sideslip_rad,
                min_speed_mps: v.min_speed_mps,
                slowing_onset_s: paper.and_then(|p| p.slowing_onset_s),
                slowing_onset_never: paper.map(|p| p.slowing_onset_s.is_none()),
                path_length_m: v.path_length_m,
                collided: v.collided,
            }
        })
        .collect()
}

fn run_job(
    scenario: &Scenario,
    job: &Job<'_>,
    registry: &BehaviourRegistry,
    interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> GridRow {
    let mut cell_scenario = scenario.clone();
    cell_scenario.sim.planner = job.cell.apply(&scenario.sim.planner);
    let options = InstanceOptions {
        planner: Some(job.planner.to_string()),
        seed: job.seed,
        keep_time_series: false,
        interrupt,
        profile: false,
    };
    let result = run_instance(
        &cell_scenario,
        &options,
        sim::recording::Recorder::disabled(),
        registry,
        |_| {},
    )
    .map(|finished| finished.outcome);
    let (collisions, error, vehicles) = match result {
        Ok(outcome) => (
            Some((outcome.safety.own_collisions() + outcome.safety.edge_contacts.len()) as u64),
            None,
            figures(&outcome),
        ),
        Err(e) => (None, Some(e.to_string()), Vec::new()),
    };
    GridRow {
        cell: job.cell,
        planner: job.planner.to_string(),
        instance: job.instance,
        seed: job.seed,
        collisions,
        error,
        vehicles,
    }
}

/// The grid's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridOutcome {
    /// Scenario name.
    pub scenario: String,
    /// Base parameter set.
    pub params: String,
    /// The axes.
    pub axes: GridAxes,
    /// Planners, the first the reference.
    pub planners: Vec<String>,
    /// Instances per cell (0: nominal only).
    pub runs: u64,
    /// Sweep seed (a string in JSON).
    #[serde(with = "crate::exact_seed")]
    pub seed: u64,
    /// Every run, in cell, planner, instance order.
    pub rows: Vec<GridRow>,
    /// Wall time (s).
    pub wall_time_s: f64,
}

/// Runs the grid in parallel; `on_run_done` is called after each run (for a progress bar).
/// The rows do not depend on the number of threads.
pub fn run_grid(plan: &GridPlan, on_run_done: &(dyn Fn() + Sync)) -> Result<GridOutcome, String> {
    if plan.planners.is_empty() {
        return Err("--planners: need at least one planner".into());
    }
    for (i, name) in plan.planners.iter().enumerate() {
        if !plan.registry.contains(name) {
            return Err(format!(
                "--planners: {}",
                crate::experiment::unknown_planner(&plan.registry, name)
            ));
        }
        if plan.planners[..i].contains(name) {
            return Err(format!("--planners: {name} is listed twice"));
        }
    }
    let cells = plan.axes.cells();
    if cells.is_empty() {
        return Err("the grid has no cell".into());
    }
    let instances: Vec<(u64, Option<u64>)> = if plan.runs == 0 {
        vec![(0, None)]
    } else {
        (0..plan.runs)
            .map(|i| (i, Some(instance_seed(plan.seed, i))))
            .collect()
    };
    // Jobs: interaction-free planners once per (prediction, sub-steps, τ).
    let mut jobs = Vec::new();
    for cell in &cells {
        for planner in &plan.planners {
            let representative = if is_interactive(planner) {
                *cell
            } else {
                GridCell {
                    interaction_time_gap_s: plan.axes.interaction_time_gap_s[0],
                    ..*cell
                }
            };
            if representative != *cell {
                continue;
            }
            for &(instance, seed) in &instances {
                jobs.push(Job {
                    cell: *cell,
                    planner: planner.as_str(),
                    instance,
                    seed,
                });
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.threads.unwrap_or(0))
        .stack_size(16 << 20)
        .build()
        .map_err(|e| e.to_string())?;
    let started = Instant::now();
    let ran: Vec<GridRow> = pool.install(|| {
        jobs.par_iter()
            .map(|job| {
                let row = run_job(&plan.scenario, job, &plan.registry, plan.interrupt.clone());
                on_run_done();
                row
            })
            .collect()
    });
    if plan
        .interrupt
        .as_ref()
        .is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed))
    {
        return Err("interrupted".into());
    }
    // Every cell gets a row for every planner and instance (shared rows copied in).
    let mut rows = Vec::new();
    for cell in &cells {
        for planner in &plan.planners {
            let source_cell = if is_interactive(planner) {
                *cell
            } else {
                GridCell {
                    interaction_time_gap_s: plan.axes.interaction_time_gap_s[0],
                    ..*cell
                }
            };
            for row in ran
                .iter()
                .filter(|r| r.cell == source_cell && r.planner == *planner)
            {
                rows.push(GridRow {
                    cell: *cell,
                    ..row.clone()
                });
            }
        }
    }
    Ok(GridOutcome {
        scenario: plan.scenario.name.clone(),
        params: plan.scenario.params.name().to_string(),
        axes: plan.axes.clone(),
        planners: plan.planners.clone(),
        runs: plan.runs,
        seed: plan.seed,
        rows,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}

/// Whether the planner named `name` reads the interaction time gap τ_I (the interactive
/// built-ins); a user's planner is taken to read it, so each of its cells runs on its own.
fn is_interactive(name: &str) -> bool {
    name.parse::<PlannerKind>()
        .map_or(true, |kind| kind.is_interactive())
}

/// Number of runs [`run_grid`] performs (for the progress bar).
pub fn job_count(plan: &GridPlan) -> u64 {
    let cells = plan.axes.cells().len() as u64;
    let shared_cells = cells / plan.axes.interaction_time_gap_s.len().max(1) as u64;
    let instances = plan.runs.max(1);
    plan.planners
        .iter()
        .map(|p| {
            if is_interactive(p) {
                cells
            } else {
                shared_cells
            }
        })
        .sum::<u64>()
        * instances
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_grid_has_48_cells_and_counts_shared_runs_once() {
        let axes = GridAxes::default();
        assert_eq!(axes.cells().len(), 48);
        let plan = GridPlan {
            scenario: Scenario::load("urgent_merge").unwrap(),
            planners: vec!["pf-cs".into(), "pf-iso".into()],
            registry: std::sync::Arc::new(BehaviourRegistry::builtin()),
            axes,
            runs: 0,
            seed: 0,
            threads: None,
            interrupt: None,
        };
        // PF-CS: 16 cells (τ_I shared), PF-ISO: 48.
        assert_eq!(job_count(&plan), 64);
    }

    #[test]
    fn a_cell_sets_exactly_its_four_parameters() {
        let base = PlannerParams::default();
        let cell = GridCell {
            predict_obstacles_in_path: false,
            substeps: false,
            path_time_gap_s: 0.0,
            interaction_time_gap_s: 1.0,
        };
        let p = cell.apply(&base);
        assert!(!p.predict_obstacles_in_path);
        assert_eq!((p.max_substep_m, p.substep_max_turn_rad), (1000.0, 0.0));
        assert_eq!(p.obstacle_time_gap_s, 0.0);
        assert_eq!(p.interaction_time_gap_s, 1.0);
        let back = GridCell {
            predict_obstacles_in_path: base.predict_obstacles_in_path,
            substeps: true,
            path_time_gap_s: base.obstacle_time_gap_s,
            interaction_time_gap_s: base.interaction_time_gap_s,
        }
        .apply(&p);
        assert_eq!(back, base);
    }
}
