//! The `merge_sim` command line: run, compare and inspect cooperative merge simulations.
//!
//! [`main`] is the stock `merge_sim` (the built-in planners); [`main_with`] is the same command
//! line with a user's [`BehaviourRegistry`]: every name it holds is accepted by `--planner` /
//! `--planners` (`run`, `compare`, `sweep`, `grid`), by a study plan's `planners` and by a
//! scenario's `driver = { planner = "…" }`, and `--help` lists them. A user's binary:
//!
//! ```no_run
//! fn main() -> std::process::ExitCode {
//!     let registry = mergesim::sim::registry::BehaviourRegistry::builtin();
//!     // registry.register("my-planner", factory)?  (see examples/own_planner_cli.rs)
//!     mergesim::cli::main_with(registry)
//! }
//! ```
//!
//! Exit codes: 0 success; 1 the simulation or an output failed, or some runs of a sweep failed;
//! 2 bad input (arguments, scenario values, presets, output paths) — reported with the
//! offending value, before any work and before anything is written; 130 / 143 interrupted by
//! SIGINT / SIGTERM (a sweep first writes what finished).
//!
//! The command line only parses its arguments (`args.rs`), calls the library
//! ([`crate::experiment::run_instance`], [`crate::sweep`], `crate::grid`, [`crate::study`], …)
//! and prints or writes what it returns. Each command is one pipeline: load, check the outputs,
//! simulate (with its observers), write.

mod args;
mod commands;
mod commonroad_command;
mod opendrive_command;
mod run_command;
mod signals;
mod simulation;
mod study_command;
mod sweep_commands;

use std::process::ExitCode;
use std::sync::Arc;

use anyhow::Context;
use sim::registry::BehaviourRegistry;

use crate::cli::args::Command;
use crate::output::write_atomically;

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

/// The stock `merge_sim`: [`main_with`] the built-in planners.
pub fn main() -> ExitCode {
    main_with(BehaviourRegistry::builtin())
}

/// The whole `merge_sim` command line with the planners of `registry` (a user's among the
/// built-ins): parses the process's arguments, runs the command and returns its exit code
/// (an invalid argument, such as a planner `registry` does not hold, prints clap's error and
/// exits with 2 before any work).
pub fn main_with(registry: BehaviourRegistry) -> ExitCode {
    let registry = Arc::new(registry);
    let cli = args::parse(&registry);
    let session = Session {
        registry,
        interrupt: signals::Interrupt::install(),
    };
    let result = match cli.command {
        None => run_command::cmd_run(&cli.run, &session),
        Some(Command::Run(args)) => run_command::cmd_run(&args, &session),
        Some(Command::Compare(args)) => commands::cmd_compare(&args, &session),
        Some(Command::Maneuver(args)) => commands::cmd_maneuver(&args),
        Some(Command::Scenario(cmd)) => commands::cmd_scenario(&cmd),
        Some(Command::Sweep(args)) => sweep_commands::cmd_sweep(&args, &session),
        Some(Command::MergeResults(args)) => sweep_commands::cmd_merge_results(&args),
        Some(Command::Grid(args)) => commands::cmd_grid(&args, &session),
        Some(Command::Study(args)) => study_command::cmd_study(&args, &session),
        Some(Command::Limits) => commands::cmd_limits(),
        Some(Command::Commonroad(cmd)) => commonroad_command::cmd_commonroad(&cmd),
        Some(Command::Opendrive(cmd)) => opendrive_command::cmd_opendrive(&cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {}", crate::error_text::error_chain(e.as_ref()));
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("error: {}", crate::error_text::error_chain(e.as_ref()));
            ExitCode::from(1)
        }
        Err(Failure::Interrupted { code, message }) => {
            eprintln!("{message}");
            ExitCode::from(code)
        }
    }
}

/// What every command runs with: the planners it may name and the interrupt flag.
pub(crate) struct Session {
    /// The planners `--planner`, study plans and scenarios may name.
    pub(crate) registry: Arc<BehaviourRegistry>,
    /// Set by SIGINT / SIGTERM.
    pub(crate) interrupt: signals::Interrupt,
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

pub(crate) fn write_output(path: &std::path::Path, text: &str) -> Result<(), Failure> {
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
        .map_err(run_failure)
}

pub(crate) fn sweep_failure(e: crate::sweep::SweepError) -> Failure {
    match e {
        crate::sweep::SweepError::Invalid(_) => input(e),
        crate::sweep::SweepError::Threads(_) => run_failure(e),
    }
}
