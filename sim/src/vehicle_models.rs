//! Vehicle models by name: what moves each car. A scenario's `[sim] vehicle_model`, a
//! vehicle's own `vehicle_model` and the CLI's `--vehicle-model` are looked up here.
//!
//! [`VehicleModelRegistry::builtin`] holds:
//!
//! | name | what moves the car | inputs from the tracker |
//! |---|---|---|
//! | `rapier` (default) | Rapier rigid body on four ray-cast wheels, Magic-Formula tyres, suspension | wheel torques and steering angle |
//! | `ks` | CommonRoad's kinematic single track | steering velocity and longitudinal acceleration |
//! | `st` | CommonRoad's single track, linear tyres (valid while \|a_y\| ≲ 0.4·μ·g) | same |
//! | `std` | CommonRoad's single-track drift model, Magic-Formula tyres that saturate at μ | same |
//!
//! The CommonRoad models and their adapter are in `vehicles::CommonRoadVehicle`; all four
//! read the same preset, and the safety checks and the recording see every model's chassis box
//! alike. A user adds a model without editing any crate:
//!
//! ```
//! use std::sync::Arc;
//! use sim::vehicle_models::{VehicleModelInput, VehicleModelRegistry};
//! use vehicles::{CommonRoadIntegration, CommonRoadModel, CommonRoadVehicle, VehicleModel};
//!
//! let mut models = VehicleModelRegistry::builtin();
//! models
//!     .register(
//!         "ks-coarse",
//!         "CommonRoad's ks model in 10 ms steps",
//!         Arc::new(|input: &mut VehicleModelInput<'_>| {
//!             let integration = CommonRoadIntegration {
//!                 ks_max_substep_s: 0.01,
//!                 ..CommonRoadIntegration::default()
//!             };
//!             let car = CommonRoadVehicle::spawn(
//!                 input.physics,
//!                 CommonRoadModel::Ks,
//!                 input.params,
//!                 integration,
//!                 input.pose_m,
//!                 input.speed_mps,
//!             )?;
//!             Ok(Box::new(car) as Box<dyn VehicleModel>)
//!         }),
//!     )
//!     .unwrap();
//! assert!(models.names().contains(&"ks-coarse"));
//! ```
//! and hands the registry to the world with `BehaviourRegistry::with_vehicle_models` (the CLI,
//! sweeps, grids and studies take that registry).

use std::sync::Arc;

use vehicles::{
    CommonRoadIntegration, CommonRoadModel, CommonRoadVehicle, PhysicsWorld, Vehicle, VehicleError,
    VehicleModel, VehicleParams,
};

use crate::config::{SimConfig, VehicleSpec};
use crate::error::SimError;

/// The name of the default vehicle model.
pub const DEFAULT_VEHICLE_MODEL: &str = "rapier";

/// What a factory gets to spawn one car.
pub struct VehicleModelInput<'a> {
    /// The physics world to put the car's body in.
    pub physics: &'a mut PhysicsWorld,
    /// The car's parameters (its preset).
    pub params: &'a VehicleParams,
    /// The CoG's spawn pose: x, y (m, road coordinates), heading (rad).
    pub pose_m: [f64; 3],
    /// The spawn speed, straight ahead (m/s).
    pub speed_mps: f64,
    /// The run's settings (μ, time step, …).
    pub config: &'a SimConfig,
    /// The vehicle.
    pub spec: &'a VehicleSpec,
}

/// Spawns one car of a model.
pub type VehicleModelFactory = Arc<
    dyn Fn(&mut VehicleModelInput<'_>) -> Result<Box<dyn VehicleModel>, VehicleError> + Send + Sync,
>;

/// Vehicle-model names → one-line descriptions and factories, in registration order.
#[derive(Clone, Default)]
pub struct VehicleModelRegistry {
    entries: Vec<(String, String, VehicleModelFactory)>,
}

impl std::fmt::Debug for VehicleModelRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VehicleModelRegistry")
            .field("names", &self.names())
            .finish()
    }
}

/// The factory of a CommonRoad model with the default integration steps.
fn commonroad_factory(model: CommonRoadModel) -> VehicleModelFactory {
    Arc::new(move |input: &mut VehicleModelInput<'_>| {
        let car = CommonRoadVehicle::spawn(
            input.physics,
            model,
            input.params,
            CommonRoadIntegration::default(),
            input.pose_m,
            input.speed_mps,
        )?;
        Ok(Box::new(car) as Box<dyn VehicleModel>)
    })
}

impl VehicleModelRegistry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// `rapier`, `ks`, `st` and `std` (module doc).
    pub fn builtin() -> Self {
        let rapier: VehicleModelFactory = Arc::new(|input: &mut VehicleModelInput<'_>| {
            let [x_m, y_m, yaw_rad] = input.pose_m;
            let car = Vehicle::spawn(
                input.physics,
                input.params,
                x_m,
                y_m,
                yaw_rad,
                input.speed_mps,
            )?;
            Ok(Box::new(car) as Box<dyn VehicleModel>)
        });
        let mut registry = Self::new();
        registry.entries.push((
            DEFAULT_VEHICLE_MODEL.into(),
            "Rapier rigid body on four ray-cast wheels, Magic-Formula tyres (default)".into(),
            rapier,
        ));
        for (model, description) in [
            (CommonRoadModel::Ks, "CommonRoad's kinematic single track"),
            (
                CommonRoadModel::St,
                "CommonRoad's single track, linear tyres (|a_y| <~ 0.4 mu g)",
            ),
            (
                CommonRoadModel::Std,
                "CommonRoad's single-track drift model, Magic-Formula tyres",
            ),
        ] {
            registry.entries.push((
                model.name().into(),
                description.into(),
                commonroad_factory(model),
            ));
        }
        registry
    }

    /// Adds `factory` under `name` with a one-line `description`. Refuses an empty name, one
    /// with whitespace, commas or quotes, and a name already taken.
    pub fn register(
        &mut self,
        name: &str,
        description: &str,
        factory: VehicleModelFactory,
    ) -> Result<(), SimError> {
        if name.is_empty() || name.contains(|c: char| c.is_whitespace() || c == ',' || c == '"') {
            return Err(SimError::InvalidField {
                field: "name".into(),
                message: format!(
                    "vehicle model name {name:?} must be non-empty, without spaces, commas or quotes"
                ),
            });
        }
        if self.contains(name) {
            return Err(SimError::InvalidField {
                field: "name".into(),
                message: format!("vehicle model name {name:?} is already registered"),
            });
        }
        self.entries
            .push((name.to_string(), description.to_string(), factory));
        Ok(())
    }

    /// Whether `name` is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.entries.iter().any(|(n, _, _)| n == name)
    }

    /// The registered names, in registration order (`rapier` first).
    pub fn names(&self) -> Vec<&str> {
        self.entries.iter().map(|(n, _, _)| n.as_str()).collect()
    }

    /// Each name with its description, in registration order.
    pub fn descriptions(&self) -> Vec<(&str, &str)> {
        self.entries
            .iter()
            .map(|(n, d, _)| (n.as_str(), d.as_str()))
            .collect()
    }

    /// The message for a name this registry does not hold: `unknown vehicle model 'NAME';
    /// valid: rapier, ks, …`.
    pub fn unknown(&self, name: &str) -> String {
        format!(
            "unknown vehicle model '{name}'; valid: {}",
            self.names().join(", ")
        )
    }

    /// Spawns a car of model `name`.
    pub fn spawn(
        &self,
        name: &str,
        input: &mut VehicleModelInput<'_>,
    ) -> Result<Box<dyn VehicleModel>, SimError> {
        let (_, _, factory) = self
            .entries
            .iter()
            .find(|(n, _, _)| n == name)
            .ok_or_else(|| SimError::InvalidScenario(self.unknown(name)))?;
        Ok(factory(input)?)
    }
}

/// The model of `spec`: its own `vehicle_model`, else the scenario's `sim.vehicle_model`; with
/// the dotted field that chose it, for errors.
pub fn model_of<'a>(config: &'a SimConfig, spec: &'a VehicleSpec) -> (&'a str, String) {
    match &spec.vehicle_model {
        Some(name) => (
            name.as_str(),
            format!("vehicles[{}].vehicle_model", spec.name),
        ),
        None => (config.vehicle_model.as_str(), "sim.vehicle_model".into()),
    }
}
