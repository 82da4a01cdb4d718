//! A binary of one's own with the whole `merge_sim` command line and one's own planner: register
//! the planner by name next to the built-in ones, hand the registry to
//! `mergesim::cli::main_with`. Every command then takes the name: `run --planner`,
//! `compare --planners`, `sweep --planners`, `grid --planners`, a study plan's `planners`, a
//! scenario file's `driver = { planner = "time-gap-cruise" }`; `--help` lists it.
//!
//! The planner is the adaptive cruise control of examples/custom_planner.rs
//! (examples/shared/time_gap_cruise.rs).
//!
//! `cargo run --release --example own_planner_cli -- compare --planners pf-iso,time-gap-cruise`

use std::process::ExitCode;

use mergesim::sim::registry::BehaviourRegistry;

#[path = "shared/time_gap_cruise.rs"]
mod time_gap_cruise;

fn main() -> ExitCode {
    let mut registry = BehaviourRegistry::builtin();
    if let Err(e) = registry.register(
        "time-gap-cruise",
        time_gap_cruise::time_gap_cruise_factory(),
    ) {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    mergesim::cli::main_with(registry)
}
