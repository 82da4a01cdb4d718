//! Which vehicles of a scenario the environment's agents drive ([`select`]), the contacts each of
//! them had ([`ContactWatch`]), and the planner a finished agent's vehicle is handed back to
//! ([`own_planner`]).

use std::sync::{Arc, Mutex};

use mergesim_types::{Behaviour, VehicleId};
use scenarios::scenario::Scenario;
use sim::config::{Driver, VehicleSpec};
use sim::registry::{BehaviourRegistry, FactoryInput};
use sim::{SimError, TickObserver};

use crate::errors::BindingError;

/// How the agents are chosen (`EnvCore(vehicle=…, agents=…, connected_agents=…)`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum AgentChoice {
    /// One agent, any vehicle: by name, or `ego` if there is one, else the first vehicle
    /// (`MergeEnv`).
    One(Option<String>),
    /// These vehicles, each a candidate ([`is_candidate`]), in this order.
    Many(Vec<String>),
    /// Every candidate, in the scenario's order.
    EveryConnected,
}

/// Whether a vehicle can be one of several agents: connected (V2V) and driven by a planner
/// (not IDM, lane keeping or a prescribed speed profile), so that a planner can take it back
/// when its agent is done.
pub(crate) fn is_candidate(spec: &VehicleSpec) -> bool {
    spec.connected && matches!(spec.driver, Driver::Planner { .. })
}

/// Why a vehicle is not a candidate (every reason), for the error message.
fn not_candidate_because(spec: &VehicleSpec) -> String {
    let driver = match &spec.driver {
        Driver::Planner { .. } => None,
        Driver::Idm => Some("it is driven by IDM, not a planner"),
        Driver::IdmMobil => Some("it is driven by IDM with MOBIL, not a planner"),
        Driver::LaneKeeping => Some("it is driven by lane keeping, not a planner"),
        Driver::Prescribed { .. } => Some("it has a prescribed speed profile, not a planner"),
    };
    let connected = (!spec.connected).then_some("it is not connected (connected = false)");
    let reasons: Vec<&str> = driver.into_iter().chain(connected).collect();
    reasons.join(" and ")
}

/// The agents' vehicle indices for `choice` (module doc); the errors name the valid choices.
pub(crate) fn select(
    scenario: &Scenario,
    choice: &AgentChoice,
) -> Result<Vec<usize>, BindingError> {
    let names: Vec<&str> = scenario.vehicles.iter().map(|v| v.name.as_str()).collect();
    let candidates: Vec<&str> = scenario
        .vehicles
        .iter()
        .filter(|v| is_candidate(v))
        .map(|v| v.name.as_str())
        .collect();
    let listed = |list: &[&str]| {
        if list.is_empty() {
            "none".to_string()
        } else {
            list.join(", ")
        }
    };
    let input = |message: String| BindingError::Input(message);
    match choice {
        AgentChoice::One(Some(name)) => names
            .iter()
            .position(|n| n == name)
            .map(|i| vec![i])
            .ok_or_else(|| {
                input(format!(
                    "vehicle {name:?}: not a vehicle of scenario {} ({})",
                    scenario.name,
                    names.join(", ")
                ))
            }),
        AgentChoice::One(None) => Ok(vec![names.iter().position(|n| *n == "ego").unwrap_or(0)]),
        AgentChoice::EveryConnected => {
            let chosen: Vec<usize> = (0..names.len())
                .filter(|&i| is_candidate(&scenario.vehicles[i]))
                .collect();
            if chosen.is_empty() {
                return Err(input(format!(
                    "scenario {}: no connected, planner-driven vehicle to be an agent (vehicles: \
                     {})",
                    scenario.name,
                    names.join(", ")
                )));
            }
            Ok(chosen)
        }
        AgentChoice::Many(list) => {
            if list.is_empty() {
                return Err(input(format!(
                    "agents: an empty list; name one or more of the connected, planner-driven \
                     vehicles of scenario {}: {}",
                    scenario.name,
                    listed(&candidates)
                )));
            }
            let mut chosen = Vec::with_capacity(list.len());
            for name in list {
                let Some(index) = names.iter().position(|n| n == name) else {
                    return Err(input(format!(
                        "agent {name:?}: not a vehicle of scenario {}; the connected, \
                         planner-driven vehicles are: {}",
                        scenario.name,
                        listed(&candidates)
                    )));
                };
                if chosen.contains(&index) {
                    return Err(input(format!("agent {name:?}: listed twice in agents")));
                }
                let spec = &scenario.vehicles[index];
                if !is_candidate(spec) {
                    return Err(input(format!(
                        "agent {name:?}: {}; an agent must be a connected, planner-driven \
                         vehicle: {}",
                        not_candidate_because(spec),
                        listed(&candidates)
                    )));
                }
                chosen.push(index);
            }
            Ok(chosen)
        }
    }
}

/// Contacts of one agent's vehicle since the last look.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Contacts {
    /// It collided with another vehicle.
    pub vehicle: bool,
    /// It touched a road edge.
    pub road_edge: bool,
}

/// The agents' contacts, in agent order.
pub(crate) type SharedContacts = Arc<Mutex<Vec<Contacts>>>;

/// Watches the world's collision reports for the agents' vehicles.
pub(crate) struct ContactWatch {
    /// The agents' vehicle ids, in agent order.
    pub agents: Vec<VehicleId>,
    /// Where their contacts go (same order).
    pub contacts: SharedContacts,
}

impl TickObserver for ContactWatch {
    fn on_collision(&mut self, ids: &[VehicleId]) {
        let mut contacts = self
            .contacts
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for (slot, agent) in self.agents.iter().enumerate() {
            if !ids.contains(agent) {
                continue;
            }
            let Some(entry) = contacts.get_mut(slot) else {
                continue;
            };
            // A collision between vehicles names both; a road-edge contact names one vehicle.
            if ids.len() >= 2 {
                entry.vehicle = true;
            } else {
                entry.road_edge = true;
            }
        }
    }
}

/// The behaviour `driver` (a planner) gives the vehicle of `input` (whose own driver is the
/// environment's `external`): what drives an agent's vehicle once it is handed back.
pub(crate) fn own_planner(
    registry: &BehaviourRegistry,
    input: &FactoryInput<'_>,
    driver: &Driver,
) -> Result<Box<dyn Behaviour>, SimError> {
    let Some(name) = driver.planner_name() else {
        return Err(SimError::InvalidScenario(format!(
            "vehicle {}: an agent's vehicle needs a planner to hand it back to",
            input.spec.name
        )));
    };
    let mut spec = input.spec.clone();
    spec.driver = driver.clone();
    let parsed = registry
        .parse_params(name, input.config, driver.params())
        .map_err(|e| {
            SimError::InvalidScenario(format!("vehicle {}: planner {name}: {e}", spec.name))
        })?;
    let own = FactoryInput {
        config: input.config,
        spec: &spec,
        lanes: input.lanes,
        params: parsed
            .as_ref()
            .map(|p| p.as_ref() as &(dyn std::any::Any + Send + Sync)),
    };
    registry.create(name, &own)
}
