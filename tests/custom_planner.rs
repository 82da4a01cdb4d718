//! A user-defined planner through the registry: implemented outside the crates, registered by
//! name, selected in a scenario, run by the library's one entry.

use std::sync::Arc;

use mergesim::experiment::{InstanceOptions, RunError, run_instance};
use mergesim::mergesim_types::{Behaviour, BehaviourError, Decision, Lane, Observation, PathPoint};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::SimError;
use mergesim::sim::config::Driver;
use mergesim::sim::recording::Recorder;
use mergesim::sim::registry::{BehaviourRegistry, FactoryInput};

/// Holds its spawn lane at a fixed speed of its own (ignoring the scenario's target).
struct FixedSpeed {
    speed_mps: f64,
    lane: Lane,
}

impl Behaviour for FixedSpeed {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        // Its spawn lane as a lane of the road (the merge road's lanes by their ids).
        let id = match self.lane {
            Lane::Upper => mergesim::mergesim_types::lanes::THROUGH_LANE_ID,
            Lane::Lower => mergesim::mergesim_types::lanes::ENDING_LANE_ID,
        };
        let lane = obs.lanes.lane(id).ok_or("no such lane")?;
        let s_m = lane.project([obs.ego.x_m, obs.ego.y_m]).s_m;
        let v = self.speed_mps;
        Ok(Decision::follow(
            (0..=20)
                .map(|i| {
                    let [x_m, y_m] = lane.point(s_m + 3.0 * i as f64, 0.0);
                    PathPoint {
                        x_m,
                        y_m,
                        speed_mps: v,
                        t_s: obs.time_s + 3.0 * i as f64 / v,
                    }
                })
                .collect(),
        ))
    }
}

fn registry() -> BehaviourRegistry {
    let mut registry = BehaviourRegistry::builtin();
    registry
        .register(
            "fixed-12",
            Arc::new(|input: &FactoryInput<'_>| {
                Ok(Box::new(FixedSpeed {
                    speed_mps: 12.0,
                    // The merge road's lanes by name ("lower" / "upper" or ids 2 / 1).
                    lane: input.spec.lane.merge_lane().unwrap(),
                }) as Box<dyn Behaviour>)
            }),
        )
        .unwrap();
    registry
}

#[test]
fn a_registered_planner_drives_its_vehicle_among_pf_iso_traffic() {
    let mut scenario = Scenario::load("urgent_merge").unwrap();
    scenario.vehicles[1].driver = Driver::planner("fixed-12");
    let finished = run_instance(
        &scenario,
        &InstanceOptions::default(),
        Recorder::disabled(),
        &registry(),
        |_| {},
    )
    .unwrap();
    let obstacle = &finished.summary.vehicles[1];
    // It slows from 15 to its own 12 m/s and holds it.
    assert!(
        (obstacle.final_speed_mps - 12.0).abs() < 0.2,
        "{obstacle:?}"
    );
    assert_eq!(finished.summary.planner, "mixed");
    // The ego still plans with PF-ISO and merges without a collision.
    assert_eq!(
        finished.summary.collisions, 0,
        "{:?}",
        finished.summary.events
    );
    assert!(
        finished
            .summary
            .events
            .iter()
            .any(|e| e.contains("ego changed lanes left"))
    );
    // The same name through the override applies it to every planner-driven vehicle (for the
    // first 8 s: the ego, held in its ending lane, would reach the taper).
    scenario.sim.duration_s = 8.0;
    let options = InstanceOptions {
        planner: Some("fixed-12".into()),
        ..InstanceOptions::default()
    };
    let all = run_instance(
        &scenario,
        &options,
        Recorder::disabled(),
        &registry(),
        |_| {},
    )
    .unwrap();
    assert_eq!(all.summary.planner, "fixed-12");
    for vehicle in &all.summary.vehicles {
        assert!((vehicle.final_speed_mps - 12.0).abs() < 0.2, "{vehicle:?}");
    }
}

#[test]
fn an_unregistered_planner_is_refused_before_the_run_with_the_valid_names() {
    let mut scenario = Scenario::load("urgent_merge").unwrap();
    scenario.vehicles[1].driver = Driver::planner("no-such-planner");
    let err = run_instance(
        &scenario,
        &InstanceOptions::default(),
        Recorder::disabled(),
        &registry(),
        |_| {},
    )
    .unwrap_err();
    match err {
        RunError::Setup(SimError::UnknownPlanner { name, valid, .. }) => {
            assert_eq!(name, "no-such-planner");
            assert!(
                valid.contains("fixed-12") && valid.contains("pf-iso"),
                "{valid}"
            );
        }
        other => panic!("{other:?}"),
    }
}
