//! The braking a planner is told it and the others can rely on (a_b of Eq. 5): each car's own
//! limit on this road, min(μ·g, its brakes'), times `planner_brake_margin`, rounded down to
//! 0.1 m/s² (docs/vehicle_models.md, "The braking the planners rely on").

mod common;

use std::sync::{Arc, Mutex};

use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::registry::{BehaviourRegistry, FactoryInput};

/// The a_b values one planner was given: its own, and its neighbours'.
#[derive(Debug, Default, Clone, PartialEq)]
struct Given {
    own_mps2: Vec<f64>,
    neighbours_mps2: Vec<f64>,
}

/// Keeps its lane at its target speed and notes the braking figures it was given.
struct Witness {
    given: Arc<Mutex<Given>>,
}

impl Behaviour for Witness {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        {
            let mut given = self.given.lock().map_err(|e| e.to_string())?;
            given.own_mps2.push(obs.ego_shape.max_brake_decel_mps2);
            given
                .neighbours_mps2
                .extend(obs.neighbours.iter().map(|n| n.shape.max_brake_decel_mps2));
        }
        let path = common::straight_path(obs, obs.ego.y_m);
        Ok(Decision::follow_and_share(path, obs))
    }
}

/// Two witnesses, 40 m apart in the upper lane, for 0.3 s; what the first was given.
fn given_to_the_first(config: SimConfig, vehicle_model: Option<&str>) -> Given {
    let given = Arc::new(Mutex::new(Given::default()));
    let first = Arc::clone(&given);
    let mut registry = BehaviourRegistry::new();
    registry
        .register(
            "witness",
            Arc::new(move |input: &FactoryInput<'_>| {
                let given = if input.spec.name == "a" {
                    Arc::clone(&first)
                } else {
                    Arc::new(Mutex::new(Given::default()))
                };
                Ok(Box::new(Witness { given }) as Box<dyn Behaviour>)
            }),
        )
        .unwrap();
    let specs: Vec<VehicleSpec> = [("a", 0.0), ("b", 40.0)]
        .into_iter()
        .map(|(name, x_m)| VehicleSpec {
            vehicle_model: vehicle_model.map(str::to_string),
            connected: true,
            ..common::spec(name, x_m, 15.0, Driver::planner("witness"))
        })
        .collect();
    let config = SimConfig {
        duration_s: 0.3,
        ..config
    };
    common::run_with(config, &specs, &registry);
    let out = given.lock().unwrap().clone();
    assert!(!out.own_mps2.is_empty() && !out.neighbours_mps2.is_empty());
    out
}

/// The single value every figure in `given` holds (own and neighbours' alike).
fn only_value(given: &Given) -> f64 {
    let first = given.own_mps2[0];
    for v in given.own_mps2.iter().chain(&given.neighbours_mps2) {
        assert_eq!(*v, first, "{given:?}");
    }
    first
}

fn with_mu(mu: f64) -> SimConfig {
    SimConfig {
        mu,
        ..SimConfig::default()
    }
}

#[test]
fn the_default_car_at_the_default_friction_relies_on_7_mps2() {
    // 0.9 · 0.8 · 9.81 = 7.06, rounded down: the value of every earlier release.
    assert_eq!(
        only_value(&given_to_the_first(SimConfig::default(), None)),
        7.0
    );
}

#[test]
fn on_a_wet_road_the_planners_rely_on_what_the_tyres_can_give() {
    // 0.9 · 0.5 · 9.81 = 4.41 → 4.4, below the 4.9 m/s² the tyres can give; with every model.
    for model in [None, Some("ks"), Some("st"), Some("std")] {
        assert_eq!(
            only_value(&given_to_the_first(with_mu(0.5), model)),
            4.4,
            "{model:?}"
        );
    }
}

#[test]
fn on_a_grippy_road_the_brakes_limit_it() {
    // μ·g = 14.7 m/s² exceeds the preset's brakes (11.5 m/s²): 0.9 · 11.5 = 10.35 → 10.3.
    assert_eq!(only_value(&given_to_the_first(with_mu(1.5), None)), 10.3);
}

#[test]
fn the_margin_is_a_parameter() {
    let config = SimConfig {
        planner_brake_margin: 0.5,
        ..SimConfig::default()
    };
    // 0.5 · 0.8 · 9.81 = 3.92 → 3.9.
    assert_eq!(only_value(&given_to_the_first(config, None)), 3.9);
    let refused = SimConfig {
        planner_brake_margin: 0.0,
        ..SimConfig::default()
    };
    let message = refused.validate().unwrap_err().to_string();
    assert!(message.contains("planner_brake_margin"), "{message}");
}
