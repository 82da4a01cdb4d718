//! A vehicle of the world with its decision making: the car (moved by its vehicle model), its tracker, its
//! behaviour (planner, human-driver model, prescribed-speed driver or a user's), the path it
//! is tracking, and the lane it is in (lane changes are events).

use mergesim_types::lanes::{LaneId, LaneRoad};
use mergesim_types::{Behaviour, PathPoint, VehicleId, VehicleShape, planning_brake_decel_mps2};
use vehicles::tracker::Tracker;
use vehicles::{VehicleModel, VehicleParams};

use crate::config::{Driver, SimConfig, VehicleSpec};
use crate::drivers::{IdmDriver, LaneKeeping, PrescribedSpeed};
use crate::error::SimError;
use crate::planner_params::{ParamsError, ParamsTable, ParsedParams};
use crate::registry::{BehaviourRegistry, FactoryInput};
use crate::shield::{RssShield, ShieldKind};

/// One vehicle and its driver.
pub struct Agent {
    /// Index in the scenario.
    pub id: VehicleId,
    /// What the scenario says of it.
    pub spec: VehicleSpec,
    /// Footprint and braking.
    pub shape: VehicleShape,
    /// The car, moved by its vehicle model (`crate::vehicle_models`).
    pub vehicle: Box<dyn VehicleModel>,
    /// Its decision making.
    pub behaviour: Box<dyn Behaviour>,
    /// Pure pursuit + PID.
    pub tracker: Tracker,
    /// The path being tracked.
    pub path: Vec<PathPoint>,
    /// The lane it is in (`crate::lane_membership`), last checked at a logged instant.
    pub lane: LaneId,
    /// The degraded mode of its last decision (events on changes).
    pub degraded_mode: Option<mergesim_types::DegradedMode>,
    /// The shield bounding its planner's decisions (`crate::shield`); `None` without one, and
    /// for human-driver models.
    pub shield: Option<RssShield>,
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
    // The planner's own parameters (`crate::planner_params`): its scenario table overlaid by
    // the vehicle's `driver.params`, read by its schema.
    let params_of = |name: &str, own: Option<&ParamsTable>| {
        registry
            .parse_params(name, config, own)
            .map_err(|e| params_error(config, spec, name, own, e))
    };
    let create = |name: &str, params: Option<&ParsedParams>| {
        let input = FactoryInput {
            config,
            spec,
            lanes,
            params: params.map(|p| p.as_ref() as &(dyn std::any::Any + Send + Sync)),
        };
        registry.create(name, &input)
    };
    Ok(match &spec.driver {
        Driver::Planner { name, params } => {
            let name = planner_override.unwrap_or(name);
            let params = if registry.contains(name) {
                params_of(name, params.as_ref())?
            } else {
                None // `create` names the unknown planner
            };
            create(name, params.as_ref())?
        }
        Driver::Prescribed {
            path_planner,
            speed_profile,
        } => {
            let params = if registry.contains(path_planner) {
                params_of(path_planner, None)?
            } else {
                None
            };
            Box::new(PrescribedSpeed {
                path_planner: create(path_planner, params.as_ref())?,
                profile: speed_profile.clone(),
            })
        }
        Driver::LaneKeeping => Box::new(LaneKeeping {
            lane: spec.lane.id(),
            d_offset_m: spec.y_offset_m,
        }),
        Driver::Idm => Box::new(IdmDriver::for_vehicle(config, spec, false)),
        Driver::IdmMobil => Box::new(IdmDriver::for_vehicle(config, spec, true)),
    })
}

/// A refused parameter table as a simulator error naming the field: the vehicle's
/// `driver.params.KEY` if its own table holds the key, else `planners.NAME.KEY`.
fn params_error(
    config: &SimConfig,
    spec: &VehicleSpec,
    planner: &str,
    own: Option<&ParamsTable>,
    e: ParamsError,
) -> SimError {
    let in_own = e
        .key
        .as_ref()
        .is_some_and(|k| own.is_some_and(|t| t.contains_key(k)));
    let key_suffix = e.key.as_ref().map(|k| format!(".{k}")).unwrap_or_default();
    let field = if in_own {
        format!("vehicles[{}].driver.params{key_suffix}", spec.name)
    } else if config.planners.contains_key(planner) {
        format!("planners.{planner}{key_suffix}")
    } else {
        format!("vehicles[{}].driver.params{key_suffix}", spec.name)
    };
    SimError::InvalidField {
        field,
        message: format!("planner {planner}: {}", e.message),
    }
}

impl Agent {
    /// Spawns vehicle `index` of the scenario on the road of `physics`: on the straight
    /// `[sim.road]` merge road at (x_m, lane centre + y_offset_m) heading +x; on a road of lanes
    /// at (s = x_m, d = y_offset_m) of its start lane, heading along the lane.
    pub fn spawn(
        config: &SimConfig,
        lanes: &std::sync::Arc<LaneRoad>,
        physics: &mut vehicles::PhysicsWorld,
        index: usize,
        spec: &VehicleSpec,
        registry: &BehaviourRegistry,
        planner_override: Option<&str>,
    ) -> Result<Self, SimError> {
        let params = VehicleParams::preset(&spec.preset)?;
        let (x_m, y_m, yaw_rad) = match (config.is_straight_merge_road(), spec.lane.merge_lane()) {
            (true, Some(lane)) => (
                spec.x_m,
                config.road.lane_center_y_m(lane) + spec.y_offset_m,
                0.0,
            ),
            _ => {
                let lane = lanes
                    .lane(spec.lane.id())
                    .ok_or_else(|| SimError::InvalidField {
                        field: format!("vehicles[{}].lane", spec.name),
                        message: format!("lane {} does not exist on the road", spec.lane),
                    })?;
                let [x, y] = lane.point(spec.x_m, spec.y_offset_m);
                (x, y, lane.heading_rad(spec.x_m))
            }
        };
        let (model, field) = crate::vehicle_models::model_of(config, spec);
        let models = registry.vehicle_models();
        if !models.contains(model) {
            return Err(SimError::InvalidField {
                field,
                message: models.unknown(model),
            });
        }
        let vehicle = models.spawn(
            model,
            &mut crate::vehicle_models::VehicleModelInput {
                physics,
                params: &params,
                pose_m: [x_m, y_m, yaw_rad],
                speed_mps: spec.speed_mps,
                config,
                spec,
            },
        )?;
        // a_b of Eq. 5: this car's own braking limit on this road, with the margin
        // (docs/vehicle_models.md, "The braking the planners rely on").
        let shape = vehicle.shape(planning_brake_decel_mps2(
            vehicle.braking_limit_mps2(config.mu),
            config.planner_brake_margin,
        ));
        let behaviour = behaviour_of(config, spec, registry, planner_override, lanes)?;
        let tracker = Tracker::new(config.tracker.clone(), &params);
        let shield = match config.shield {
            ShieldKind::Rss if behaviour.is_planner() => {
                Some(RssShield::new(config.rss.clone(), config.planner_period_s))
            }
            ShieldKind::Rss | ShieldKind::None => None,
        };
        Ok(Self {
            id: index as VehicleId,
            spec: spec.clone(),
            shape,
            vehicle,
            behaviour,
            tracker,
            path: Vec::new(),
            lane: spec.lane.id(),
            degraded_mode: None,
            shield,
        })
    }
}
