//! A vehicle of the world with its decision making: the Rapier vehicle, its tracker, its
//! behaviour (planner, human-driver model, prescribed-speed driver or a user's), the path it
//! is tracking, and whether it has crossed the lane divider yet.

use mergesim_types::{Behaviour, Lane, PathPoint, VehicleId, VehicleShape};
use vehicles::{Tracker, Vehicle, VehicleParams};

use crate::config::{Driver, SimConfig, VehicleSpec};
use crate::drivers::{IdmDriver, LaneKeeping, PrescribedSpeed};
use crate::error::SimError;
use crate::registry::{BehaviourRegistry, FactoryInput};

/// One vehicle and its driver.
pub struct Agent {
    /// Index in the scenario.
    pub id: VehicleId,
    /// What the scenario says of it.
    pub spec: VehicleSpec,
    /// Footprint and braking.
    pub shape: VehicleShape,
    /// The Rapier vehicle.
    pub vehicle: Vehicle,
    /// Its decision making.
    pub behaviour: Box<dyn Behaviour>,
    /// Pure pursuit + PID.
    pub tracker: Tracker,
    /// The path being tracked.
    pub path: Vec<PathPoint>,
    /// Whether a vehicle that started in the ending lane has crossed the divider yet.
    pub merged: bool,
    /// The degraded mode of its last decision (events on changes).
    pub degraded_mode: Option<String>,
}

/// The behaviour of `spec`: its planner from the registry (or `planner_override`, which
/// replaces every `driver = { planner = … }`), a prescribed-speed driver around its path
/// planner, or one of the simulator's own drivers.
pub fn behaviour_of(
    config: &SimConfig,
    spec: &VehicleSpec,
    registry: &BehaviourRegistry,
    planner_override: Option<&str>,
    lanes: &std::sync::Arc<mergesim_types::lanes::LaneRoad>,
) -> Result<Box<dyn Behaviour>, SimError> {
    let input = FactoryInput {
        config,
        spec,
        lanes,
    };
    Ok(match &spec.driver {
        Driver::Planner(name) => registry.create(planner_override.unwrap_or(name), &input)?,
        Driver::Prescribed {
            path_planner,
            speed_profile,
        } => Box::new(PrescribedSpeed {
            path_planner: registry.create(path_planner, &input)?,
            profile: speed_profile.clone(),
        }),
        Driver::LaneKeeping => Box::new(LaneKeeping {
            lane: spec.lane,
            y_offset_m: spec.y_offset_m,
        }),
        Driver::Idm => Box::new(IdmDriver {
            params: config.idm.clone(),
            lane: spec.lane,
            y_offset_m: spec.y_offset_m,
        }),
    })
}

impl Agent {
    /// Spawns vehicle `index` of the scenario on the road of `physics`.
    pub fn spawn(
        config: &SimConfig,
        physics: &mut vehicles::PhysicsWorld,
        index: usize,
        spec: &VehicleSpec,
        registry: &BehaviourRegistry,
        planner_override: Option<&str>,
        lanes: &std::sync::Arc<mergesim_types::lanes::LaneRoad>,
    ) -> Result<Self, SimError> {
        let params = VehicleParams::preset(&spec.preset)?;
        let y_m = config.road.lane_center_y_m(spec.lane) + spec.y_offset_m;
        let vehicle = Vehicle::spawn(physics, &params, spec.x_m, y_m, 0.0, spec.speed_mps)?;
        let shape = vehicle.shape(VehicleShape::default().max_brake_decel_mps2);
        let behaviour = behaviour_of(config, spec, registry, planner_override, lanes)?;
        let tracker = Tracker::new(config.tracker.clone(), &params);
        Ok(Self {
            id: index as VehicleId,
            spec: spec.clone(),
            shape,
            vehicle,
            behaviour,
            tracker,
            path: Vec::new(),
            merged: spec.lane == Lane::Upper,
            degraded_mode: None,
        })
    }
}
