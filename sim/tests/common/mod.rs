//! Pieces shared by the `sim` integration tests: a vehicle spec, a straight path, and a run
//! with a registry of one's own behaviours. Each test file uses some of them.
#![allow(dead_code)]

use mergesim_types::{Lane, Observation, PathPoint};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::recording::Recorder;
use sim::registry::BehaviourRegistry;
use sim::{RunOptions, RunOutcome, World};

/// A BMW 320i in the upper lane at `x_m`, at `speed_mps` (its target speed too), driven by
/// `driver`, not connected.
pub fn spec(name: &str, x_m: f64, speed_mps: f64, driver: Driver) -> VehicleSpec {
    VehicleSpec {
        name: name.into(),
        preset: "bmw_320i".into(),
        vehicle_model: None,
        lane: Lane::Upper.into(),
        x_m,
        y_offset_m: 0.0,
        speed_mps,
        target_speed_mps: speed_mps,
        driver,
        connected: false,
        goal: None,
        route: None,
    }
}

/// 21 points 3 m apart straight ahead along X from the ego at `y_m`, at its target speed.
pub fn straight_path(obs: &Observation<'_>, y_m: f64) -> Vec<PathPoint> {
    let v = obs.target_speed_mps;
    (0..=20)
        .map(|i| PathPoint {
            x_m: obs.ego.x_m + 3.0 * i as f64,
            y_m,
            speed_mps: v,
            t_s: obs.time_s + 3.0 * i as f64 / v,
        })
        .collect()
}

/// Runs `specs` on `config` with the behaviours of `registry`, unrecorded, to its end.
pub fn run_with(
    config: SimConfig,
    specs: &[VehicleSpec],
    registry: &BehaviourRegistry,
) -> RunOutcome {
    let world = World::with_registry(
        config,
        specs,
        &RunOptions::default(),
        Recorder::disabled(),
        registry,
    )
    .unwrap();
    world.run(|_| {}).unwrap()
}
