//! The closed-loop merge simulation: the `World` (rapier physics, vehicles and their behaviours),
//! the V2V bus, exact parry safety checks, the observers of a run (metrics, time series, Rerun
//! recording), the simulator's own drivers and the registry of planners by name.
//!
//! # Public API
//! - A run: [`World`] built from a [`config::SimConfig`] and its [`config::VehicleSpec`]s
//!   (checked by [`config::validate_vehicles`]), run with [`RunOptions`] to a [`RunOutcome`]
//!   (with [`TimeSeriesRow`]s, [`RecordedPose`]s, [`PlannerStats`]) or a [`SimError`].
//! - The road: [`road_config`] ([`road_config::LaneRoadConfig`], [`road_config::StartLane`], a
//!   CommonRoad map [`road_config::CommonRoadRoad`]), recorded traffic ([`recorded_traffic`]),
//!   routes ([`route`]), goals ([`goal`]) and the drawing of a road ([`road_drawing`]).
//! - Who drives: each vehicle's [`config::Driver`]; planners by name in a
//!   [`registry::BehaviourRegistry`] of [`registry::BehaviourFactory`]s (given a
//!   [`registry::FactoryInput`]), with their parameter tables ([`PlannerParameters`],
//!   [`ParamsTable`], [`ParamsError`]); the simulator's own drivers ([`drivers`], [`idm`]).
//! - What moves each car: vehicle models by name ([`vehicle_models`]: `rapier`, `ks`, `st`,
//!   `std`, or one's own), chosen by `sim.vehicle_model` or a vehicle's `vehicle_model`.
//! - Watching a run: a [`TickObserver`] sees [`VehicleView`]s, [`PlanView`]s and
//!   [`SimEvent`]s; metrics ([`metrics`], [`paper_metrics`]), safety checks ([`safety`]), the
//!   V2V bus ([`v2v`]), phase timings ([`profile`]) and Rerun recordings ([`recording`]).
//! - Helpers: the seeded generator [`rng`] and the neighbour search [`spatial`].
//! - The plain data and the interface every driver implements ([`Behaviour`](mergesim_types::Behaviour),
//!   [`Observation`](mergesim_types::Observation), [`Decision`](mergesim_types::Decision), roads
//!   made of lanes [`lanes`](mergesim_types::lanes)) are [`mergesim_types`]': spelled
//!   `mergesim_types::Behaviour` and so on (the simulator does not re-export them).
//!
//! Each item has one path: a module is public when it holds more than what the crate root
//! names, and then its items are reached through it (`sim::config::SimConfig`).
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
pub mod mobil;
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
pub mod shield;
pub mod spatial;
pub mod traffic_metrics;
pub mod v2v;
pub mod vehicle_models;
pub(crate) mod world;

pub use error::SimError;
pub use event::SimEvent;
pub use observer::{PlanView, TickObserver, VehicleView};
pub use outcome::{PlannerStats, RecordedPose, RunOutcome, TimeSeriesRow};
pub use planner_params::{ParamsError, ParamsTable, PlannerParameters};
pub use world::{RunOptions, World};
