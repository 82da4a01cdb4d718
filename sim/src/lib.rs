//! The closed-loop merge simulation: the `World` (rapier physics, vehicles and their behaviours),
//! the V2V bus, exact parry safety checks, the observers of a run (metrics, time series, Rerun
//! recording), the simulator's own drivers and the registry of planners by name.
//!
//! # Public API
//! - A run: [`World`] built from a [`SimConfig`] and its [`VehicleSpec`]s (checked by
//!   [`validate_vehicles`]), run with [`RunOptions`] to a [`RunOutcome`] (with
//!   [`TimeSeriesRow`]s, [`RecordedPose`]s, [`PlannerStats`]) or a [`SimError`].
//! - The road: [`LaneRoadConfig`] ([`StartLane`]), a CommonRoad map [`CommonRoadRoad`], recorded
//!   traffic ([`recorded_traffic`]), routes ([`route`]), goals ([`goal`]) and the drawing of a
//!   road ([`road_drawing`]).
//! - Who drives: each vehicle's [`Driver`]; planners by name in a [`BehaviourRegistry`] of
//!   [`BehaviourFactory`]s (given a [`FactoryInput`]), with their parameter tables
//!   ([`PlannerParameters`], [`ParamsTable`], [`ParamsError`]); the simulator's own drivers
//!   ([`drivers`], [`idm`]).
//! - Watching a run: a [`TickObserver`] sees [`VehicleView`]s, [`PlanView`]s and
//!   [`SimEvent`]s; metrics ([`metrics`], [`paper_metrics`]), safety checks ([`safety`]), the
//!   V2V bus ([`v2v`]), phase timings ([`profile`]) and Rerun recordings ([`recording`]).
//! - Helpers: the seeded generator [`rng`] and the neighbour search [`spatial`].
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
pub use observer::{PlanView, TickObserver, VehicleView};
pub use outcome::{PlannerStats, RecordedPose, RunOutcome, TimeSeriesRow};
pub use planner_params::{ParamsError, ParamsTable, PlannerParameters};
pub use registry::{BehaviourFactory, BehaviourRegistry, FactoryInput};
pub use road_config::{CommonRoadRoad, LaneRoadConfig, StartLane};
pub use world::{RunOptions, World};
