//! The closed-loop merge simulation: the `World` (rapier physics, vehicles and their behaviours),
//! the V2V bus, exact parry safety checks, the observers of a run (metrics, time series, Rerun
//! recording), the simulator's own drivers and the registry of planners by name.
#![warn(missing_docs)]

pub(crate) mod agent;
pub(crate) mod body_state;
pub mod config;
pub mod drivers;
pub(crate) mod error;
pub(crate) mod event;
pub mod goal;
pub mod idm;
pub(crate) mod lane_membership;
pub mod metrics;
pub(crate) mod observer;
pub(crate) mod outcome;
pub mod paper_metrics;
pub(crate) mod planner_params;
pub(crate) mod planner_stats;
pub mod profile;
pub(crate) mod recorded_motion;
pub mod recorded_traffic;
pub mod recording;
pub(crate) mod recording_observer;
pub mod registry;
pub mod rng;
pub mod road_config;
pub mod road_drawing;
pub mod route;
pub(crate) mod run_log;
pub mod safety;
pub mod spatial;
pub mod v2v;
pub(crate) mod world;

pub use config::{Driver, SimConfig, VehicleSpec, validate_vehicles};
pub use error::SimError;
pub use event::SimEvent;
/// Roads made of lanes (what `Observation::lanes` is): re-exported for planners written against
/// the simulator.
pub use mergesim_types::lanes;
pub use mergesim_types::{
    Behaviour, BehaviourError, Decision, DegradedMode, GridSpec, Lane, MergeRoad, Neighbour,
    Observation, OptimiserReport, PathPoint, SharedLocalPath, TimedWaypoint, VehicleId,
    VehicleShape, VehicleState,
};
pub use observer::{PlanView, TickObserver, VehicleView};
pub use outcome::{PlannerStats, RecordedPose, RunOutcome, TimeSeriesRow};
pub use planner_params::{ParamsError, ParamsTable, PlannerParameters};
pub use registry::{BehaviourFactory, BehaviourRegistry, FactoryInput};
pub use road_config::{CommonRoadRoad, LaneRoadConfig, StartLane};
pub use world::{RunOptions, World};
