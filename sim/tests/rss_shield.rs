//! The RSS shield in closed loop (`[sim] shield = "rss"`): it stops a planner that is blind to
//! the car ahead from running into it, changes nothing where no pair is ever RSS-dangerous, and
//! leaves human-driver models alone.

mod common;

use std::sync::Arc;

use mergesim_types::{Behaviour, BehaviourError, Decision, Lane, Observation};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::registry::{BehaviourRegistry, FactoryInput};
use sim::shield::ShieldKind;
use sim::{RunOutcome, SimEvent};

/// A planner blind to everybody: straight ahead along its own lateral position at its target
/// speed.
struct Blind;

impl Behaviour for Blind {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        Ok(Decision::follow_and_share(
            common::straight_path(obs, obs.ego.y_m),
            obs,
        ))
    }
}

fn run(specs: &[VehicleSpec], shield: ShieldKind, duration_s: f64) -> RunOutcome {
    let mut registry = BehaviourRegistry::builtin();
    registry
        .register(
            "blind",
            Arc::new(|_: &FactoryInput<'_>| Ok(Box::new(Blind) as Box<dyn Behaviour>)),
        )
        .unwrap();
    let config = SimConfig {
        duration_s,
        shield,
        ..SimConfig::default()
    };
    common::run_with(config, specs, &registry)
}

fn interventions(outcome: &RunOutcome) -> Vec<&SimEvent> {
    outcome
        .events
        .iter()
        .filter(|e| matches!(e, SimEvent::ShieldIntervened { .. }))
        .collect()
}

/// A blind car at 25 m/s 60 m behind a blind car at 10 m/s, both in the upper lane.
fn closing_in(driver: Driver) -> Vec<VehicleSpec> {
    vec![
        common::spec("rear", 0.0, 25.0, driver.clone()),
        common::spec("front", 60.0, 10.0, driver),
    ]
}

#[test]
fn the_shield_stops_a_blind_planner_from_running_into_the_car_ahead() {
    let specs = closing_in(Driver::planner("blind"));
    let unshielded = run(&specs, ShieldKind::None, 8.0);
    assert!(
        !unshielded.safety.collisions.is_empty(),
        "the blind rear car was expected to hit the front one"
    );
    assert!(interventions(&unshielded).is_empty());

    let shielded = run(&specs, ShieldKind::Rss, 8.0);
    assert!(
        shielded.safety.collisions.is_empty(),
        "{:?}",
        shielded.safety.collisions
    );
    let events = interventions(&shielded);
    // At t = 0 the 55.5 m gap is short of the safe 122 m (25 → 10 m/s, ρ = 1 s): the rear
    // car's shield intervenes at once, with both responses (nothing known before).
    let first = events.first().map(ToString::to_string).unwrap_or_default();
    assert!(
        first.contains("t = 0.00 s: the shield of rear intervened (longitudinal+lateral"),
        "{events:?}"
    );
    // It braked: the rear car's smallest speed is far below its 25 m/s.
    let rear = shielded.vehicles.iter().find(|v| v.id == "rear").unwrap();
    assert!(rear.min_speed_mps < 12.0, "{}", rear.min_speed_mps);
}

#[test]
fn where_no_pair_is_ever_dangerous_the_shield_changes_nothing() {
    // Side by side in the two lanes at the same speed: 1.7 m apart side to side, 0.725 m safe.
    // For 4 s: the lower lane's taper (from 160 m) stays beyond the reach of the edge check
    // (the safe gap to a standing object at 20 m/s, 90.8 m, from at most 80 m).
    let specs = vec![
        common::spec("upper", 0.0, 20.0, Driver::planner("blind")),
        VehicleSpec {
            lane: Lane::Lower.into(),
            ..common::spec("lower", 0.0, 20.0, Driver::planner("blind"))
        },
    ];
    let without = run(&specs, ShieldKind::None, 4.0);
    let with = run(&specs, ShieldKind::Rss, 4.0);
    assert!(interventions(&with).is_empty(), "{:?}", with.events);
    assert_eq!(
        with.safety.min_gap_m.map(f64::to_bits),
        without.safety.min_gap_m.map(f64::to_bits)
    );
    for (a, b) in with.vehicles.iter().zip(&without.vehicles) {
        assert_eq!(a.path_length_m.to_bits(), b.path_length_m.to_bits());
        assert_eq!(a.final_speed_mps.to_bits(), b.final_speed_mps.to_bits());
    }
}

#[test]
fn human_drivers_are_not_shielded() {
    // The same closing-in with IDM drivers: RSS-dangerous at once, but IDM is a human-driver
    // model, not a planner: no shield, no intervention.
    let outcome = run(&closing_in(Driver::Idm), ShieldKind::Rss, 3.0);
    assert!(interventions(&outcome).is_empty(), "{:?}", outcome.events);
}

#[test]
fn a_blind_planner_heading_into_a_closing_lane_is_stopped_before_the_edge() {
    // Alone in the lower lane, blind, at 20 m/s: without the shield it drives into the taper's
    // edge; with it, the edge ahead is a standing object and the car stops short of it.
    let specs = vec![VehicleSpec {
        lane: Lane::Lower.into(),
        ..common::spec("lower", 0.0, 20.0, Driver::planner("blind"))
    }];
    let without = run(&specs, ShieldKind::None, 15.0);
    assert!(!without.safety.edge_contacts.is_empty());
    let with = run(&specs, ShieldKind::Rss, 15.0);
    assert!(
        with.safety.edge_contacts.is_empty(),
        "{:?}",
        with.safety.edge_contacts
    );
    let events = interventions(&with);
    assert!(
        events
            .iter()
            .any(|e| e.to_string().contains("the road's edge ahead")),
        "{events:?}"
    );
    let car = &with.vehicles[0];
    assert!(car.final_speed_mps < 0.5, "{}", car.final_speed_mps);
}
