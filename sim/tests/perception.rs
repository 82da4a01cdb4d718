//! What a vehicle's behaviour is given: the others within the perception range, and the shared
//! paths of the connected vehicles within the V2V range of their senders.

mod common;

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex};

use mergesim_types::{Behaviour, BehaviourError, Decision, Observation, VehicleId};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::registry::{BehaviourRegistry, FactoryInput};

/// What one vehicle was given over the run: neighbour ids and shared-path sender ids.
#[derive(Debug, Default)]
struct Seen {
    neighbours: BTreeSet<VehicleId>,
    senders: BTreeSet<VehicleId>,
}

/// Holds its lane at its target speed, broadcasts its path and notes what it was given.
struct Witness {
    seen: Arc<Mutex<Seen>>,
}

impl Behaviour for Witness {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        {
            let mut seen = self.seen.lock().map_err(|e| e.to_string())?;
            seen.neighbours.extend(obs.neighbours.iter().map(|n| n.id));
            seen.senders
                .extend(obs.shared_paths.iter().map(|p| p.vehicle_id));
        }
        let lane_y_m = obs
            .lanes
            .lane(mergesim_types::lanes::THROUGH_LANE_ID)
            .map_or(obs.ego.y_m, |l| {
                let s_m = l.project([obs.ego.x_m, obs.ego.y_m]).s_m;
                l.point(s_m, 0.0)[1]
            });
        let path = common::straight_path(obs, lane_y_m);
        Ok(Decision::follow_and_share(path, obs))
    }
}

/// Runs four witnesses in the upper lane at x = 0, 200, 270 and 350 m for 0.5 s and returns
/// what the first one (at 0 m) was given.
fn seen_by_the_first(config: SimConfig) -> Seen {
    let seen = Arc::new(Mutex::new(Seen::default()));
    let first = Arc::clone(&seen);
    let mut registry = BehaviourRegistry::new();
    registry
        .register(
            "witness",
            Arc::new(move |input: &FactoryInput<'_>| {
                let seen = if input.spec.name == "a" {
                    Arc::clone(&first)
                } else {
                    Arc::new(Mutex::new(Seen::default()))
                };
                Ok(Box::new(Witness { seen }) as Box<dyn Behaviour>)
            }),
        )
        .unwrap();
    let specs: Vec<VehicleSpec> = [("a", 0.0), ("b", 200.0), ("c", 270.0), ("d", 350.0)]
        .into_iter()
        .map(|(name, x_m)| VehicleSpec {
            connected: true,
            ..common::spec(name, x_m, 15.0, Driver::planner("witness"))
        })
        .collect();
    let config = SimConfig {
        duration_s: 0.5,
        ..config
    };
    common::run_with(config, &specs, &registry);
    std::mem::take(&mut *seen.lock().unwrap())
}

#[test]
fn a_vehicle_beyond_the_perception_range_is_not_given_to_the_planner() {
    let config = SimConfig::default();
    assert_eq!(config.perception_range_m, 250.0);
    assert_eq!(config.v2v.range_m, 300.0);
    let seen = seen_by_the_first(config);
    // b (200 m) is perceived; c (270 m) and d (350 m) are beyond 250 m.
    assert_eq!(seen.neighbours, BTreeSet::from([1]));
    // b's and c's paths arrive (within 300 m of their senders); d's does not.
    assert_eq!(seen.senders, BTreeSet::from([1, 2]));
}

#[test]
fn without_the_ranges_every_vehicle_is_given_to_the_planner() {
    let defaults = SimConfig::default();
    let config = SimConfig {
        perception_range_m: 1e5,
        v2v: sim::v2v::V2vParams {
            range_m: 1e5,
            ..defaults.v2v.clone()
        },
        ..defaults
    };
    let seen = seen_by_the_first(config);
    assert_eq!(seen.neighbours, BTreeSet::from([1, 2, 3]));
    assert_eq!(seen.senders, BTreeSet::from([1, 2, 3]));
}
