//! The steps the commands share: load the scenario of `--scenario` (step 1 of every pipeline)
//! and simulate one instance of it with its observers (step 3: the recording, the kept time
//! series that become the CSV rows and the GIF frames, the progress line).

use anyhow::Context;
use planner::ParameterSet;
use scenarios::scenario::Scenario;
use sim::recording::{Recorder, RecorderParams};

use crate::cli::{Failure, Session, args, input, interrupted, run_failure};
use crate::experiment::{Finished, InstanceOptions, RunError, planner_label, run_instance};

/// Loads the scenario of `--scenario`, with `--params`, `--recorded-traffic`, `--duration`,
/// `--vehicle-model` and `--shield` applied, and checks its planners and their parameter tables against `registry` (a name
/// or a table the registry refuses is bad input, with the file, line and field).
pub(crate) fn load_source(
    source: &args::ScenarioArgs,
    registry: &sim::registry::BehaviourRegistry,
) -> Result<Scenario, Failure> {
    let mut scenario = load_scenario(&source.scenario, source.params)?;
    if let Some(mode) = source.recorded_traffic {
        scenario = scenario.with_recorded_traffic(mode).map_err(input)?;
    }
    if let Some(duration_s) = source.duration {
        scenario = scenario.with_duration(duration_s).map_err(input)?;
    }
    if let Some(model) = &source.vehicle_model {
        scenario = scenario.with_vehicle_model(model);
    }
    if let Some(shield) = source.shield {
        scenario.sim.shield = shield;
    }
    scenario.check_planners(registry).map_err(input)?;
    let traffic = &scenario.sim.recorded_traffic;
    if !traffic.is_empty() {
        let recording_end_s = traffic
            .vehicles
            .iter()
            .filter(|v| v.states.len() > 1)
            .filter_map(|v| v.states.last().map(|s| s.time_s))
            .fold(f64::NEG_INFINITY, f64::max);
        if recording_end_s.is_finite() && scenario.sim.duration_s > recording_end_s + 1e-9 {
            eprintln!(
                "warning: the run lasts {:.2} s, past the recording's end at {recording_end_s:.2} s: \
                 each recorded vehicle leaves the run when its recording ends",
                scenario.sim.duration_s
            );
        }
    }
    Ok(scenario)
}

/// Loads a scenario and switches it to `params` if given.
pub(crate) fn load_scenario(
    name_or_path: &str,
    params: Option<ParameterSet>,
) -> Result<Scenario, Failure> {
    let scenario = Scenario::load(name_or_path).map_err(input)?;
    match params {
        Some(set) => scenario.with_parameter_set(set).map_err(input),
        None => Ok(scenario),
    }
}

fn progress_printer(enabled: bool, label: String) -> impl FnMut(f64) {
    let mut last = -1i64;
    move |fraction: f64| {
        if !enabled {
            return;
        }
        let percent = (fraction * 100.0).floor() as i64;
        if percent != last {
            last = percent;
            eprint!("\r{label}: {percent:3}%");
            if percent >= 100 {
                eprintln!();
            }
        }
    }
}

/// What one `simulate` call runs and keeps.
#[derive(Default)]
pub(crate) struct Simulation<'a> {
    /// Planner override (a registered name).
    pub(crate) planner: Option<&'a str>,
    /// Instance seed (None: the nominal scenario).
    pub(crate) seed: Option<u64>,
    /// Recording path.
    pub(crate) rrd: Option<&'a std::path::Path>,
    /// Keep the time series (CSV, figures).
    pub(crate) keep_time_series: bool,
    /// A progress line on stderr.
    pub(crate) show_progress: bool,
    /// Time the phases of the tick.
    pub(crate) profile: bool,
    /// Vehicles with fields and received paths in the recording (None: all).
    pub(crate) record_detail: Option<usize>,
    /// The vehicle the recording's follow view follows (None: the default, `ego`).
    pub(crate) follow: Option<&'a str>,
    /// Write the lanes' ids in the recording.
    pub(crate) lane_ids: bool,
}

/// Runs one instance of `scenario` (the library's `run_instance`) with the session's planners,
/// a recording if asked for and a progress line on a terminal: a scenario the world refuses is
/// bad input, a failure while running is not.
pub(crate) fn simulate(
    scenario: &Scenario,
    what: &Simulation<'_>,
    session: &Session,
) -> Result<Finished, Failure> {
    let interrupt = &session.interrupt;
    let Simulation {
        planner,
        seed,
        rrd,
        keep_time_series,
        show_progress,
        profile,
        record_detail,
        follow,
        lane_ids,
    } = *what;
    let label = planner_label(scenario, planner);
    let recorder = match rrd {
        Some(path) => Recorder::new_file_with_params(
            path,
            "mergesim",
            RecorderParams {
                detail_vehicles: record_detail,
                follow: follow.map_or_else(|| RecorderParams::default().follow, str::to_string),
                lane_ids,
                ..RecorderParams::default()
            },
        )
        .with_context(|| format!("cannot create recording {}", path.display()))
        .map_err(run_failure)?,
        None => Recorder::disabled(),
    };
    let options = InstanceOptions {
        planner: planner.map(str::to_string),
        seed,
        keep_time_series,
        interrupt: Some(interrupt.flag.clone()),
        profile,
    };
    let progress = progress_printer(show_progress, format!("{} {label}", scenario.name));
    run_instance(scenario, &options, recorder, &session.registry, progress).map_err(|e| match e {
        RunError::Setup(e) => input(e),
        RunError::Run(sim::SimError::Interrupted { t_s }) => interrupted(
            interrupt,
            &format!(
                "run stopped at t = {t_s:.2} s; nothing written, the partial recording deleted"
            ),
        ),
        RunError::Run(e) => run_failure(e),
    })
}
