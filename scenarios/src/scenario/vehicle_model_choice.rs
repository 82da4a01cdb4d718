//! Which vehicle model moves each car: `[sim] vehicle_model` for all, a vehicle's own
//! `vehicle_model` for one (`sim::vehicle_models`), and the CLI's `--vehicle-model` for every
//! car of a run ([`Scenario::with_vehicle_model`]).

use sim::registry::BehaviourRegistry;

use super::{Line, Scenario, ScenarioError};
use crate::source_location::line_of;

impl Scenario {
    /// This scenario with every car moved by vehicle model `name` (`--vehicle-model`): the
    /// scenario's `sim.vehicle_model` becomes `name` and the vehicles' own choices are dropped.
    /// The name is checked by [`Scenario::check_vehicle_models`].
    pub fn with_vehicle_model(&self, name: &str) -> Self {
        let mut scenario = self.clone();
        scenario.sim.vehicle_model = name.to_string();
        for vehicle in &mut scenario.vehicles {
            vehicle.vehicle_model = None;
        }
        scenario
    }

    /// Checks that `registry` holds every vehicle model the scenario names (`sim.vehicle_model`
    /// and each vehicle's `vehicle_model`); the error names the file, line and field and lists
    /// the registered models. Run it before any work ([`Scenario::check_planners`] does).
    pub fn check_vehicle_models(&self, registry: &BehaviourRegistry) -> Result<(), ScenarioError> {
        let models = registry.vehicle_models();
        let origin = self
            .source
            .as_ref()
            .map(|s| s.origin.clone())
            .unwrap_or_else(|| self.name.clone());
        let text = self.source.as_ref().map(|s| s.text.as_str());
        let mut named = vec![(
            self.sim.vehicle_model.as_str(),
            vec!["sim".to_string(), "vehicle_model".to_string()],
            "sim.vehicle_model".to_string(),
        )];
        for (i, vehicle) in self.vehicles.iter().enumerate() {
            if let Some(name) = &vehicle.vehicle_model {
                named.push((
                    name.as_str(),
                    vec!["vehicles".into(), i.to_string(), "vehicle_model".into()],
                    format!("vehicles[{}].vehicle_model", vehicle.name),
                ));
            }
        }
        for (name, at, field) in named {
            if !models.contains(name) {
                return Err(ScenarioError::Invalid {
                    origin,
                    line: Line(text.and_then(|t| line_of(t, &at))),
                    message: format!("{field}: {}", models.unknown(name)),
                    field: Some(field),
                });
            }
        }
        Ok(())
    }
}
