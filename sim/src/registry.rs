//! Planners by name: the registry a scenario's `driver = { planner = "NAME" }`, `--planner NAME`
//! and a prescribed-speed driver's `path_planner` are looked up in.
//!
//! [`BehaviourRegistry::builtin`] holds the paper's planners (`pf-cs`, `pf-sp`, `pf-sp-eq10`,
//! `pf-iso`, `pf-iso-pred`). A user adds their own without editing any crate:
//!
//! ```
//! use std::sync::Arc;
//! use sim::registry::{BehaviourRegistry, FactoryInput};
//! use sim::{Behaviour, BehaviourError, Decision, Observation};
//!
//! struct Cruise;
//! impl Behaviour for Cruise {
//!     fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
//!         let v = obs.target_speed_mps;
//!         let path = (0..=10)
//!             .map(|i| sim::PathPoint {
//!                 x_m: obs.ego.x_m + 5.0 * i as f64,
//!                 y_m: obs.ego.y_m,
//!                 speed_mps: v,
//!                 t_s: obs.time_s + 5.0 * i as f64 / v,
//!             })
//!             .collect();
//!         Ok(Decision::follow(path))
//!     }
//! }
//!
//! let mut registry = BehaviourRegistry::builtin();
//! registry
//!     .register("cruise", Arc::new(|_: &FactoryInput<'_>| Ok(Box::new(Cruise) as Box<dyn Behaviour>)))
//!     .unwrap();
//! assert!(registry.names().contains(&"cruise"));
//! ```

use std::collections::BTreeMap;
use std::sync::Arc;

use planner::{PfPlanner, PlannerKind};

use crate::config::{SimConfig, VehicleSpec};
use crate::error::SimError;
use mergesim_types::Behaviour;

/// What a factory gets to build one vehicle's behaviour.
#[derive(Clone, Copy, Debug)]
pub struct FactoryInput<'a> {
    /// The run's settings (road, μ, planner parameters, …).
    pub config: &'a SimConfig,
    /// The vehicle.
    pub spec: &'a VehicleSpec,
    /// The road as lanes, built once per world (the road every `Observation::lanes` carries).
    pub lanes: &'a Arc<mergesim_types::lanes::LaneRoad>,
}

/// Builds a behaviour for one vehicle.
pub type BehaviourFactory =
    Arc<dyn Fn(&FactoryInput<'_>) -> Result<Box<dyn Behaviour>, SimError> + Send + Sync>;

/// Planner names → factories (module doc). Names are kept sorted, so listing them is
/// deterministic.
#[derive(Clone, Default)]
pub struct BehaviourRegistry {
    factories: BTreeMap<String, BehaviourFactory>,
}

impl std::fmt::Debug for BehaviourRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BehaviourRegistry")
            .field("names", &self.names())
            .finish()
    }
}

/// The factory of a potential-field planner of `kind`.
fn pf_factory(kind: PlannerKind) -> BehaviourFactory {
    Arc::new(move |input: &FactoryInput<'_>| {
        PfPlanner::new(kind, input.config.planner.clone(), Arc::clone(input.lanes))
            .map(|p| match &input.spec.route {
                Some(route) => p.with_route(route),
                None => p,
            })
            .map(|p| Box::new(p) as Box<dyn Behaviour>)
            .map_err(|source| SimError::Planner {
                vehicle: input.spec.name.clone(),
                source,
            })
    })
}

impl BehaviourRegistry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// The paper's planners under their names (`PlannerKind::name`).
    pub fn builtin() -> Self {
        let mut registry = Self::new();
        for kind in PlannerKind::ALL {
            registry
                .factories
                .insert(kind.name().to_string(), pf_factory(kind));
        }
        registry
    }

    /// Adds `factory` under `name`. Refuses an empty name, one with whitespace, commas or
    /// quotes, and a name already taken (a built-in cannot be replaced by accident).
    pub fn register(&mut self, name: &str, factory: BehaviourFactory) -> Result<(), SimError> {
        if name.is_empty() || name.contains(|c: char| c.is_whitespace() || c == ',' || c == '"') {
            return Err(SimError::InvalidScenario(format!(
                "planner name {name:?} must be non-empty, without spaces, commas or quotes"
            )));
        }
        if self.factories.contains_key(name) {
            return Err(SimError::InvalidScenario(format!(
                "planner name {name:?} is already registered"
            )));
        }
        self.factories.insert(name.to_string(), factory);
        Ok(())
    }

    /// Every registered name, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.factories.keys().map(String::as_str).collect()
    }

    /// Whether `name` is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.factories.contains_key(name)
    }

    /// The behaviour `name` for one vehicle.
    pub fn create(
        &self,
        name: &str,
        input: &FactoryInput<'_>,
    ) -> Result<Box<dyn Behaviour>, SimError> {
        let factory = self
            .factories
            .get(name)
            .ok_or_else(|| SimError::UnknownPlanner {
                vehicle: input.spec.name.clone(),
                name: name.to_string(),
                valid: self.names().join(", "),
            })?;
        factory(input)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_names_are_the_planner_kinds_and_duplicates_are_refused() {
        let mut registry = BehaviourRegistry::builtin();
        let mut expected: Vec<&str> = PlannerKind::ALL.iter().map(|k| k.name()).collect();
        expected.sort_unstable();
        assert_eq!(registry.names(), expected);
        let factory = pf_factory(PlannerKind::PfCs);
        assert!(registry.register("pf-iso", factory.clone()).is_err());
        assert!(registry.register("my planner", factory.clone()).is_err());
        assert!(registry.register("", factory.clone()).is_err());
        registry.register("mine", factory).unwrap();
        assert!(registry.contains("mine"));
    }
}
