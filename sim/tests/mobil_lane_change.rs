//! An IDM driver with MOBIL leaves the lane that ends: at once on an empty road, and only
//! into a gap when the through lane is busy, stopping short of the lane's end meanwhile. Without
//! MOBIL it keeps its lane.

mod common;

use mergesim_types::Lane;
use sim::RunOutcome;
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::registry::BehaviourRegistry;

/// Runs `specs` with the default parameters (`driver = "idm-mobil"`: IDM + MOBIL).
fn run(specs: &[VehicleSpec], duration_s: f64) -> RunOutcome {
    let config = SimConfig {
        duration_s,
        ..SimConfig::default()
    };
    common::run_with(config, specs, &BehaviourRegistry::builtin())
}

/// The lane changes of the run as (vehicle, time, x).
fn lane_changes(outcome: &RunOutcome) -> Vec<String> {
    outcome
        .events
        .iter()
        .map(ToString::to_string)
        .filter(|e| e.contains("changed lanes"))
        .collect()
}

/// The x of a lane-change event ("… at x = 12.3 m, …").
fn change_x_m(event: &str) -> f64 {
    event
        .split("at x = ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|x| x.parse().ok())
        .unwrap()
}

fn in_lower_lane(name: &str, x_m: f64, driver: Driver) -> VehicleSpec {
    VehicleSpec {
        lane: Lane::Lower.into(),
        ..common::spec(name, x_m, 20.0, driver)
    }
}

#[test]
fn on_an_empty_road_it_leaves_the_ending_lane() {
    let outcome = run(&[in_lower_lane("merger", 0.0, Driver::IdmMobil)], 20.0);
    let changes = lane_changes(&outcome);
    assert_eq!(changes.len(), 1, "{changes:?}");
    assert!(
        changes[0].contains("merger changed lanes left"),
        "{changes:?}"
    );
    // At once: within the first 50 m, far before the taper at 160 m.
    assert!(change_x_m(&changes[0]) < 50.0, "{changes:?}");
    assert!(outcome.safety.collisions.is_empty());
    assert!(
        outcome.safety.edge_contacts.is_empty(),
        "{:?}",
        outcome.safety.edge_contacts
    );
}

#[test]
fn without_mobil_the_idm_driver_follows_its_lane_into_the_taper() {
    // The plain IDM driver holds the lower lane to its end and is carried into the through lane
    // by the lane's successor only in the taper (x > 160 m), touching the road's edge: the
    // behaviour MOBIL replaces.
    let outcome = run(&[in_lower_lane("keeper", 0.0, Driver::Idm)], 20.0);
    let changes = lane_changes(&outcome);
    assert_eq!(changes.len(), 1, "{changes:?}");
    assert!(change_x_m(&changes[0]) > 160.0, "{changes:?}");
    assert!(!outcome.safety.edge_contacts.is_empty());
}

#[test]
fn into_a_busy_lane_it_waits_for_a_gap_and_does_not_crash() {
    // Eight IDM cars at 20 m/s, 14 m apart (9.5 m gaps) beside and ahead of the merger: no gap
    // is safe until the last has passed.
    let mut specs: Vec<VehicleSpec> = (0..8)
        .map(|k| {
            common::spec(
                &format!("through{k}"),
                60.0 - 14.0 * k as f64,
                20.0,
                Driver::Idm,
            )
        })
        .collect();
    specs.push(in_lower_lane("merger", 0.0, Driver::IdmMobil));
    let outcome = run(&specs, 40.0);
    let changes = lane_changes(&outcome);
    assert_eq!(changes.len(), 1, "{changes:?}");
    assert!(
        changes[0].contains("merger changed lanes left"),
        "{changes:?}"
    );
    assert!(
        outcome.safety.collisions.is_empty(),
        "{:?}",
        outcome.safety.collisions
    );
    assert!(
        outcome.safety.edge_contacts.is_empty(),
        "{:?}",
        outcome.safety.edge_contacts
    );
    // It slowed for the lane's end while the platoon passed.
    let merger = outcome.vehicles.iter().find(|v| v.id == "merger").unwrap();
    assert!(merger.min_speed_mps < 15.0, "{}", merger.min_speed_mps);
}
