//! What a simulation is made of: the shared settings and the vehicles to spawn.

mod driver;

use std::collections::BTreeMap;

use mergesim_types::MergeRoad;
use planner::params::PlannerParams;
use serde::{Deserialize, Serialize};
use vehicles::tracker::TrackerParams;

use mergesim_types::bounds::{self, Bound};
use mergesim_types::lanes::LaneId;

pub use driver::Driver;

use crate::error::SimError;
use crate::goal::Goal;
use crate::idm::IdmParams;
use crate::mobil::MobilParams;
use crate::planner_params::ParamsTable;
use crate::recorded_traffic::RecordedTraffic;
use crate::road_config::{LaneRoadConfig, StartLane, build_lane_road};
use crate::safety::SafetyParams;
use crate::shield::{RssParams, ShieldKind};
use crate::v2v::V2vParams;

/// Settings shared by every vehicle of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// The parametric merge road (`[sim.road]`, the paper's straight road): the road of lanes
    /// unless `lane_road` gives another one (`curved_merge` bends this one).
    pub road: MergeRoad,
    /// A road of lanes instead of `road` (`[sim.lane_road]`; `crate::road_config`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lane_road: Option<LaneRoadConfig>,
    /// Tire–road friction coefficient μ.
    pub mu: f64,
    /// The share of its car's braking limit on this road (min(μ·g, its brakes')) that a
    /// planner relies on, as a_b of Eq. 5, rounded down to 0.1 m/s²
    /// (`mergesim_types::planning_brake_decel_mps2`; docs/vehicle_models.md). 0.9: 7 m/s² for
    /// the presets at μ = 0.8.
    pub planner_brake_margin: f64,
    /// What moves every car without its own `vehicle_model` (`crate::vehicle_models`):
    /// `rapier` (the default: rigid body on ray-cast wheels), `ks`, `st` or `std` (CommonRoad's
    /// models), or a registered model of one's own.
    pub vehicle_model: String,
    /// Physics step (s): read once to build the physics world, which owns the step during a run
    /// (`vehicles::PhysicsWorld::dt_s`; the world's time and periods are counted in its steps).
    pub dt_s: f64,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Planning period of every vehicle (s).
    pub planner_period_s: f64,
    /// Period of metrics, CSV rows and recording (s).
    pub log_period_s: f64,
    /// Period of the potential-field images in the recording (s).
    pub field_log_period_s: f64,
    /// Period of the parry safety checks (s); rounded to whole physics steps.
    pub safety_period_s: f64,
    /// A vehicle's behaviour is given the others whose centres are within this distance (m):
    /// the reach of its sensors. 250 m, a long-range automotive radar's (docs/parameters.md).
    pub perception_range_m: f64,
    /// V2V bus.
    pub v2v: V2vParams,
    /// The potential-field planners' parameters, scenario level: the `--params` set's with the
    /// `[sim.planners.pf]` (alias `[sim.planner]`), `[sim.planners.pf-iso]` and
    /// `[sim.planners.pf-sp]` tables on top (the scenario loader merges them;
    /// `planner::params_tables`). A vehicle's `driver = { params = … }` gives its own planner
    /// its own copy (`Driver::Planner::params`); everything else that reads this
    /// (V2V horizon, metrics, the field images, …) reads this scenario-level value.
    pub planner: PlannerParams,
    /// Each other planner's own table, by registered name (`[sim.planners.NAME]`): read by the
    /// planner's schema when its vehicles are built (`crate::planner_params`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub planners: BTreeMap<String, ParamsTable>,
    /// Path / speed tracker.
    pub tracker: TrackerParams,
    /// Collision, gap and TTC thresholds.
    pub safety: SafetyParams,
    /// Intelligent Driver Model of the human-driven (`driver = "idm"` and `"idm-mobil"`)
    /// vehicles.
    pub idm: IdmParams,
    /// MOBIL lane changes of the `driver = "idm-mobil"` vehicles (`[sim.mobil]`). Written out
    /// only when it differs from the defaults, so a scenario without it keeps its canonical
    /// form (and its sweep fingerprint).
    #[serde(skip_serializing_if = "MobilParams::is_default")]
    pub mobil: MobilParams,
    /// The safety shield the planner-driven vehicles wear (`crate::shield`): `"none"` (the
    /// default) or `"rss"`. Written out only when on.
    #[serde(skip_serializing_if = "ShieldKind::is_none")]
    pub shield: ShieldKind,
    /// Responsibility-Sensitive Safety's parameters for `shield = "rss"` (`[sim.rss]`). Written
    /// out only when they differ from the defaults.
    #[serde(skip_serializing_if = "RssParams::is_default")]
    pub rss: RssParams,
    /// Recorded vehicles replayed beside the simulated ones (`crate::recorded_traffic`): filled
    /// by the scenario loader from the road's source file, never written in a scenario.
    #[serde(skip)]
    pub recorded_traffic: RecordedTraffic,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            road: MergeRoad::default(),
            lane_road: None,
            mu: 0.8,
            planner_brake_margin: 0.9,
            vehicle_model: crate::vehicle_models::DEFAULT_VEHICLE_MODEL.to_string(),
            dt_s: 0.002,
            duration_s: 25.0,
            planner_period_s: 0.1,
            log_period_s: 0.05,
            field_log_period_s: 0.5,
            safety_period_s: 0.01,
            perception_range_m: DEFAULT_PERCEPTION_RANGE_M,
            v2v: V2vParams::default(),
            planner: PlannerParams::default(),
            planners: BTreeMap::new(),
            tracker: TrackerParams::default(),
            safety: SafetyParams::default(),
            idm: IdmParams::default(),
            mobil: MobilParams::default(),
            shield: ShieldKind::None,
            rss: RssParams::default(),
            recorded_traffic: RecordedTraffic::default(),
        }
    }
}

/// Allowed ranges of the `[sim]` table's own fields (README "Limits"); every period must also
/// be at least one physics step.
pub const SIM_BOUNDS: &[Bound] = &[
    Bound::above("mu", 0.0, 2.0, ""),
    Bound::above("planner_brake_margin", 0.0, 1.0, ""),
    Bound::closed("dt_s", 1e-4, 0.02, "s"),
    Bound::above("duration_s", 0.0, 3600.0, "s"),
    Bound::closed("planner_period_s", 1e-4, 10.0, "s"),
    Bound::closed("log_period_s", 1e-4, 10.0, "s"),
    Bound::closed("field_log_period_s", 1e-4, 10.0, "s"),
    Bound::closed("safety_period_s", 1e-4, 10.0, "s"),
    Bound::closed("perception_range_m", 1.0, 1e5, "m"),
];

/// Default of [`SimConfig::perception_range_m`]: long-range automotive radars reach 250 m
/// (e.g. Bosch LRR4, Continental ARS 408); docs/parameters.md gives the criterion.
pub(crate) const DEFAULT_PERCEPTION_RANGE_M: f64 = 250.0;

/// Allowed ranges of a vehicle's own fields (`[[vehicles]]`); `x_m` must also lie on the road
/// and the body must fit on it at spawn (checked by the scenario loader).
pub const VEHICLE_BOUNDS: &[Bound] = &[
    Bound::closed("y_offset_m", -1.0, 1.0, "m"),
    Bound::closed("speed_mps", 0.0, 60.0, "m/s"),
    Bound::closed("target_speed_mps", 0.5, 60.0, "m/s"),
];

/// Most vehicles a scenario may hold.
pub const MAX_VEHICLES: usize = 200;

/// Most vehicle physics steps of one run (vehicles × duration_s / dt_s): at ≈ 2 µs per vehicle
/// and step, about 7 minutes of physics.
pub const MAX_VEHICLE_STEPS: f64 = 2e8;

/// Most planning cycles of one run (vehicles × duration_s / planner_period_s): at ≈ 0.2–5 ms
/// per cycle, at most a few hours in the densest traffic.
pub const MAX_PLANNING_CYCLES: f64 = 2e6;

/// Most pair checks of the safety monitor in one run (vehicle pairs × duration_s /
/// safety_period_s).
pub const MAX_PAIR_CHECKS: f64 = 1e9;

impl SimConfig {
    /// The run's road of lanes: `lane_road` if given, else `road` (`crate::road_config`).
    /// Refuses inconsistent lane data ([`SimError::Road`] names the lane and the field).
    pub fn lanes(&self) -> Result<mergesim_types::lanes::LaneRoad, SimError> {
        build_lane_road(&self.road, self.lane_road.as_ref())
    }

    /// The CommonRoad file the road comes from, if it does (`crate::road_config`).
    pub fn commonroad_road(&self) -> Option<&crate::road_config::CommonRoadRoad> {
        self.lane_road.as_ref()?.commonroad.as_ref()
    }

    /// True if the road is the `[sim.road]` merge road, straight (no `lane_road`): vehicle
    /// positions are then world x (`x_m`) and offsets from the lane centre (`y_offset_m`).
    pub fn is_straight_merge_road(&self) -> bool {
        self.lane_road.is_none()
    }

    /// Checks every field against its bounds and the periods against the physics step; the
    /// error names the field and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        self.road.validate()?;
        self.lanes()?;
        bounds::check_all(
            "",
            SIM_BOUNDS,
            &[
                ("mu", self.mu),
                ("planner_brake_margin", self.planner_brake_margin),
                ("dt_s", self.dt_s),
                ("duration_s", self.duration_s),
                ("planner_period_s", self.planner_period_s),
                ("log_period_s", self.log_period_s),
                ("field_log_period_s", self.field_log_period_s),
                ("safety_period_s", self.safety_period_s),
                ("perception_range_m", self.perception_range_m),
            ],
        )?;
        let defaults = SimConfig::default();
        for (name, value, default) in [
            ("duration_s", self.duration_s, defaults.duration_s),
            (
                "planner_period_s",
                self.planner_period_s,
                defaults.planner_period_s,
            ),
            ("log_period_s", self.log_period_s, defaults.log_period_s),
            (
                "field_log_period_s",
                self.field_log_period_s,
                defaults.field_log_period_s,
            ),
            (
                "safety_period_s",
                self.safety_period_s,
                defaults.safety_period_s,
            ),
        ] {
            if value < self.dt_s {
                // A period left at its default is not what the user changed: name dt_s.
                return Err(if value == default {
                    SimError::invalid(
                        "dt_s",
                        self.dt_s,
                        format!(
                            "the physics step must not exceed {name} = {value} s (its default); \
                             shorten dt_s or set {name}"
                        ),
                    )
                } else {
                    SimError::invalid(
                        name,
                        value,
                        format!("must be at least one physics step, dt_s = {} s", self.dt_s),
                    )
                });
            }
        }
        self.v2v.validate()?;
        self.idm.validate()?;
        self.mobil.validate()?;
        self.rss.validate()?;
        self.safety.validate().map_err(SimError::from)?;
        self.tracker.validate()?;
        self.planner.validate()?;
        Ok(())
    }
}

/// One vehicle to spawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSpec {
    /// Unique name (the paper's scenario: `ego`, `obstacle`).
    pub name: String,
    /// Vehicle preset (`bmw_320i`, `ford_escort`, `vw_vanagon`).
    pub preset: String,
    /// What moves this car (`crate::vehicle_models`: `rapier`, `ks`, `st`, `std`, or a
    /// registered model of one's own); `None`: the scenario's `sim.vehicle_model`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_model: Option<String>,
    /// Starting lane: `"lower"` / `"upper"` (the merge road's lanes 2 and 1) or a lane id
    /// (`lanelet = ID` on a CommonRoad road: a lanelet's id is its lane's).
    #[serde(alias = "lanelet")]
    pub lane: StartLane,
    /// Initial longitudinal position of the centre of gravity (m): on the straight `[sim.road]`
    /// merge road its x; on a road of lanes (`[sim.lane_road]`) its arc length s along the start
    /// lane's centreline, from the lane's first vertex (`s_m` is read as this).
    #[serde(alias = "s_m")]
    pub x_m: f64,
    /// Lateral offset from the lane centre (m, positive to the left; on a road of lanes the
    /// lane-frame offset d; `d_m` is read as this).
    #[serde(default, alias = "d_m")]
    pub y_offset_m: f64,
    /// Initial speed (m/s).
    pub speed_mps: f64,
    /// Target speed V_target (m/s).
    pub target_speed_mps: f64,
    /// Who drives.
    pub driver: Driver,
    /// Whether it sends and receives shared local paths.
    #[serde(default = "default_true")]
    pub connected: bool,
    /// Its goal (`crate::goal`): checked every log period; `goal_reached` and `goal_time_s` in
    /// the outcome. A CommonRoad scenario's ego gets its planning problem's goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal: Option<Goal>,
    /// The lanes its planner drives along, in order (`crate::route`; a road of lanes only):
    /// a potential-field planner targets the route's lane at or after its own. None: the
    /// lane-end rule (its own lane, unless it ends).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route: Option<Vec<LaneId>>,
}

fn default_true() -> bool {
    true
}

/// Checks the vehicle list against the configuration; the error names the vehicle and field.
pub fn validate_vehicles(config: &SimConfig, specs: &[VehicleSpec]) -> Result<(), SimError> {
    if specs.is_empty() || specs.len() > MAX_VEHICLES {
        return Err(SimError::invalid(
            "vehicles",
            specs.len() as f64,
            format!("a scenario needs 1 to {MAX_VEHICLES} vehicles"),
        ));
    }
    // Bounded work: a run that cannot finish in reasonable time is refused before it starts.
    let vehicles = specs.len() as f64;
    let pairs = vehicles * (vehicles - 1.0) / 2.0;
    for (what, amount, limit, field, value) in [
        (
            "vehicle physics steps (vehicles × duration_s / dt_s)",
            vehicles * config.duration_s / config.dt_s,
            MAX_VEHICLE_STEPS,
            "dt_s",
            config.dt_s,
        ),
        (
            "planning cycles (vehicles × duration_s / planner_period_s)",
            vehicles * config.duration_s / config.planner_period_s,
            MAX_PLANNING_CYCLES,
            "planner_period_s",
            config.planner_period_s,
        ),
        (
            "safety pair checks (vehicle pairs × duration_s / safety_period_s)",
            pairs * config.duration_s / config.safety_period_s,
            MAX_PAIR_CHECKS,
            "safety_period_s",
            config.safety_period_s,
        ),
    ] {
        if amount > limit {
            return Err(SimError::invalid(
                field,
                value,
                format!(
                    "with duration_s = {} s and {} vehicles the run needs {amount:.3e} {what}, \
                     more than the limit {limit:.0e}: lengthen {field} or shorten duration_s",
                    config.duration_s,
                    specs.len()
                ),
            ));
        }
    }
    // The road of lanes, when it is not the straight merge road (positions in its frame).
    let lanes = if config.is_straight_merge_road() {
        None
    } else {
        Some(config.lanes()?)
    };
    for (i, spec) in specs.iter().enumerate() {
        if specs[..i].iter().any(|other| other.name == spec.name) {
            return Err(SimError::InvalidField {
                field: format!("vehicles[#{i}].name"),
                message: format!("duplicate vehicle name {:?}", spec.name),
            });
        }
        if spec.name.is_empty() || spec.name.contains([',', '"', '\n']) {
            return Err(SimError::InvalidField {
                field: format!("vehicles[#{i}].name"),
                message: format!(
                    "vehicle name {:?} must be non-empty and free of commas, quotes and newlines",
                    spec.name
                ),
            });
        }
        vehicles::VehicleParams::preset(&spec.preset).map_err(|e| SimError::InvalidField {
            field: format!("vehicles[{}].preset", spec.name),
            message: e.to_string(),
        })?;
        let field = |name: &str| format!("vehicles[{}].{name}", spec.name);
        if let Driver::Prescribed { speed_profile, .. } = &spec.driver {
            speed_profile.validate(&field("driver.prescribed"))?;
        }
        // On a CommonRoad road the offset is bounded by the lanelet (below), not by ±1 m: a
        // recorded initial state may lie anywhere across its lanelet.
        let on_commonroad = config.commonroad_road().is_some();
        let bounds_list: &[Bound] = if on_commonroad {
            &VEHICLE_BOUNDS[1..]
        } else {
            VEHICLE_BOUNDS
        };
        let values = [
            ("y_offset_m", spec.y_offset_m),
            ("speed_mps", spec.speed_mps),
            ("target_speed_mps", spec.target_speed_mps),
        ];
        bounds::check_all(
            &format!("vehicles[{}]", spec.name),
            bounds_list,
            if on_commonroad {
                &values[1..]
            } else {
                &values[..]
            },
        )?;
        if let Some(lanes) = lanes.as_ref() {
            let Some(lane) = lanes.lane(spec.lane.id()) else {
                return Err(SimError::InvalidField {
                    field: field("lane"),
                    message: format!(
                        "lane {} does not exist on the road (its lanes: {})",
                        spec.lane,
                        lanes
                            .lanes()
                            .iter()
                            .map(|l| l.id().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            };
            if !(spec.x_m.is_finite() && spec.x_m >= 0.0 && spec.x_m <= lane.length_m()) {
                return Err(SimError::invalid(
                    field("x_m"),
                    spec.x_m,
                    format!(
                        "on a road of lanes x_m is the arc length along lane {}: it must lie \
                         in [0, {:.3}] m",
                        spec.lane,
                        lane.length_m()
                    ),
                ));
            }
            if on_commonroad {
                let (right_m, left_m) = (lane.right_d_m(spec.x_m), lane.left_d_m(spec.x_m));
                if !(spec.y_offset_m.is_finite()
                    && right_m <= spec.y_offset_m
                    && spec.y_offset_m <= left_m)
                {
                    return Err(SimError::invalid(
                        field("y_offset_m"),
                        spec.y_offset_m,
                        format!(
                            "the centre must lie on lanelet {}: at s = {:.3} m its offset d must \
                             lie in [{right_m:.3}, {left_m:.3}] m",
                            spec.lane, spec.x_m
                        ),
                    ));
                }
            }
            if let Some(route) = &spec.route {
                check_route(lanes, spec, route)?;
            }
            continue;
        }
        if spec.route.is_some() {
            return Err(SimError::InvalidField {
                field: field("route"),
                message: "a route needs a road of lanes ([sim.lane_road])".into(),
            });
        }
        if spec.lane.merge_lane().is_none() {
            return Err(SimError::InvalidField {
                field: field("lane"),
                message: format!(
                    "lane {}: the [sim.road] merge road has lanes \"lower\" (2) and \"upper\" (1)",
                    spec.lane
                ),
            });
        }
        if !(spec.x_m.is_finite()
            && spec.x_m >= config.road.start_x_m
            && spec.x_m <= config.road.end_x_m)
        {
            return Err(SimError::invalid(
                field("x_m"),
                spec.x_m,
                format!(
                    "must lie on the road, in [road.start_x_m, road.end_x_m] = [{}, {}] m",
                    config.road.start_x_m, config.road.end_x_m
                ),
            ));
        }
    }
    Ok(())
}

/// A route starts at the vehicle's lane and goes on, lane by lane, to a successor or a
/// same-direction neighbour (`crate::route::next_lanes`).
fn check_route(
    lanes: &mergesim_types::lanes::LaneRoad,
    spec: &VehicleSpec,
    route: &[LaneId],
) -> Result<(), SimError> {
    let field = format!("vehicles[{}].route", spec.name);
    if route.first() != Some(&spec.lane.id()) {
        return Err(SimError::InvalidField {
            field,
            message: format!("a route must start at the vehicle's lane {}", spec.lane),
        });
    }
    for pair in route.windows(2) {
        if !crate::route::next_lanes(lanes, pair[0]).contains(&pair[1]) {
            return Err(SimError::InvalidField {
                field,
                message: format!(
                    "lane {} does not follow lane {} (neither a successor nor a same-direction \
                     neighbour)",
                    pair[1], pair[0]
                ),
            });
        }
    }
    Ok(())
}
