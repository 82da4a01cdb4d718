//! `merge_sim`: run, compare and inspect cooperative merge simulations.
//!
//! Exit codes: 0 success; 1 the simulation or an output failed, or some runs of a sweep failed;
//! 2 bad input (arguments, scenario values, presets, output paths) — reported with the
//! offending value, before any work and before anything is written; 130 / 143 interrupted by
//! SIGINT / SIGTERM (a sweep first writes what finished).
//!
//! This binary only parses the command line ([`args`]), calls the library
//! (`mergesim::experiment::run_instance`, `mergesim::sweep`, `mergesim::grid`, …) and prints
//! or writes what it returns ([`commands`]).

mod args;
mod commands;
mod commonroad_command;
mod opendrive_command;
mod signals;
mod study_command;
mod sweep_commands;

use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use mergesim::experiment::{Finished, InstanceOptions, RunError, planner_label, run_instance};
use mergesim::output::write_atomically;
use planner::ParameterSet;
use scenarios::Scenario;
use sim::BehaviourRegistry;
use sim::recording::{Recorder, RecorderParams};

use crate::args::{Cli, Command};

/// `print!` that ends the process quietly when stdout is closed (output piped into `head`)
/// instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stdout(), $($arg)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

/// `println!` with the same treatment of a closed stdout as [`out!`].
macro_rules! outln {
    ($($arg:tt)*) => {{
        out!($($arg)*);
        out!("\n");
    }};
}

pub(crate) use {out, outln};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let interrupt = signals::Interrupt::install();
    let result = match cli.command {
        None => commands::cmd_run(&cli.run, &interrupt),
        Some(Command::Run(args)) => commands::cmd_run(&args, &interrupt),
        Some(Command::Compare(args)) => commands::cmd_compare(&args, &interrupt),
        Some(Command::Maneuver(args)) => commands::cmd_maneuver(&args),
        Some(Command::Scenario(cmd)) => commands::cmd_scenario(&cmd),
        Some(Command::Sweep(args)) => sweep_commands::cmd_sweep(&args, &interrupt),
        Some(Command::MergeResults(args)) => sweep_commands::cmd_merge_results(&args),
        Some(Command::Grid(args)) => commands::cmd_grid(&args, &interrupt),
        Some(Command::Study(args)) => study_command::cmd_study(&args, &interrupt),
        Some(Command::Limits) => commands::cmd_limits(),
        Some(Command::Commonroad(cmd)) => commonroad_command::cmd_commonroad(&cmd),
        Some(Command::Opendrive(cmd)) => opendrive_command::cmd_opendrive(&cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
        Err(Failure::Interrupted { code, message }) => {
            eprintln!("{message}");
            ExitCode::from(code)
        }
    }
}

/// An error with its exit code: 2 for bad input, 1 for failures while running, 128 + the
/// signal's number when interrupted.
pub(crate) enum Failure {
    Input(anyhow::Error),
    Run(anyhow::Error),
    Interrupted { code: u8, message: String },
}

/// The failure of a command stopped by `interrupt` (`what` is done).
pub(crate) fn interrupted(interrupt: &signals::Interrupt, what: &str) -> Failure {
    Failure::Interrupted {
        code: interrupt.exit_code(),
        message: format!("interrupted by {}: {what}", interrupt.name()),
    }
}

pub(crate) fn input<E: Into<anyhow::Error>>(e: E) -> Failure {
    Failure::Input(e.into())
}

pub(crate) fn run_failure<E: Into<anyhow::Error>>(e: E) -> Failure {
    Failure::Run(e.into())
}

/// Loads the scenario of `--scenario`, with `--params`, `--recorded-traffic` and `--duration`
/// applied.
pub(crate) fn load_source(source: &args::ScenarioArgs) -> Result<Scenario, Failure> {
    let mut scenario = load_scenario(&source.scenario, source.params)?;
    if let Some(mode) = source.recorded_traffic {
        scenario = scenario.with_recorded_traffic(mode).map_err(input)?;
    }
    if let Some(duration_s) = source.duration {
        scenario = scenario.with_duration(duration_s).map_err(input)?;
    }
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

/// Runs one instance of `scenario` (the library's `run_instance`), with a progress line on a
/// terminal: a scenario the world refuses is bad input, a failure while running is not.
pub(crate) fn simulate(
    scenario: &Scenario,
    what: &Simulation<'_>,
    interrupt: &signals::Interrupt,
) -> Result<Finished, Failure> {
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
    run_instance(
        scenario,
        &options,
        recorder,
        &BehaviourRegistry::builtin(),
        progress,
    )
    .map_err(|e| match e {
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

pub(crate) fn write_output(path: &std::path::Path, text: &str) -> Result<(), Failure> {
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
        .map_err(run_failure)
}

pub(crate) fn sweep_failure(e: mergesim::sweep::SweepError) -> Failure {
    match e {
        mergesim::sweep::SweepError::Invalid(_) => input(e),
        mergesim::sweep::SweepError::Threads(_) => run_failure(e),
    }
}
