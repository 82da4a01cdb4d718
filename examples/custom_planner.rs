//! Adding your own planner without editing any crate: implement `Behaviour`, register it by
//! name, select it in a scenario, run.
//!
//! The planner here (examples/shared/time_gap_cruise.rs) is a simple adaptive cruise control
//! (ACC) on any road of lanes: it keeps the
//! lane it is in (its centreline, through `Observation::lanes`) and its target speed, but never
//! closes in on a vehicle ahead in its lane (or within a metre of entering it) faster than a
//! constant time gap allows. It broadcasts its path, so the PF-ISO ego
//! sees where it is going. The example runs the paper's urgent merge with the obstacle driven by
//! this ACC against the ego's PF-ISO and prints the run summary.
//!
//! `cargo run --release --example custom_planner`

use mergesim::experiment::{InstanceOptions, run_instance};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::config::Driver;
use mergesim::sim::recording::Recorder;
use mergesim::sim::registry::BehaviourRegistry;

#[path = "shared/time_gap_cruise.rs"]
mod time_gap_cruise;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 1. Register the planner under a name, next to the built-in ones.
    let mut registry = BehaviourRegistry::builtin();
    registry.register(
        "time-gap-cruise",
        time_gap_cruise::time_gap_cruise_factory(),
    )?;

    // 2. Select it in a scenario: the paper's urgent merge, its obstacle driven by the new
    //    planner (in a TOML file: `driver = { planner = "time-gap-cruise" }`).
    let mut scenario = Scenario::load("urgent_merge")?;
    for vehicle in &mut scenario.vehicles {
        if vehicle.name == "obstacle" {
            vehicle.driver = Driver::planner("time-gap-cruise");
        }
    }

    // 3. Run it, the ego with PF-ISO (the scenario's), and print the summary.
    let finished = run_instance(
        &scenario,
        &InstanceOptions::default(),
        Recorder::disabled(),
        &registry,
        |_| {},
    )?;
    print!("{}", finished.summary.table());
    for event in &finished.summary.events {
        println!("event: {event}");
    }
    println!("collisions: {}", finished.summary.collisions);
    Ok(())
}
