//! Plain data shared by mergesim's crates: the merge road's geometry, roads made of lanes (the
//! curvilinear lane frame, [`lanes`]), a vehicle's state and
//! shape, path points and the shared local paths exchanged over V2V, a sampling grid, and the one
//! typed error for a parameter out of range.
//!
//! No physics, no optimiser, no logging: the planner, the vehicle model and the simulator all
//! speak these types, and depend on nothing else to do so.
//!
//! # Public API
//! - A vehicle: [`VehicleState`], [`VehicleShape`], [`VehicleId`], and a neighbour as another
//!   vehicle sees it, [`Neighbour`].
//! - Paths: [`PathPoint`], [`TimedWaypoint`] and the V2V message [`SharedLocalPath`].
//! - The merge road: [`MergeRoad`] and its [`Lane`]s; roads made of lanes: [`lanes`]
//!   ([`lanes::LaneRoad`] built from a [`lanes::LaneRoadSpec`]).
//! - The interface every driver implements: [`Behaviour`], fed an [`Observation`], answering a
//!   [`Decision`] (with [`DegradedMode`], [`OptimiserReport`], [`BehaviourError`]).
//! - A sampling grid [`GridSpec`] (at most [`MAX_GRID_CELLS`] cells), a parameter's range
//!   [`bounds::Bound`] ([`bounds`]) and the error for a value out of range, [`InvalidParameter`].
//! - Helpers: [`angle::wrap_angle_rad`] (the one angle wrap), [`files::read_regular_text`],
//!   [`percentile::nearest_rank_percentile`] and the merge road's limits [`ROAD_BOUNDS`] and
//!   [`MERGE_SECTION_LENGTH_M`].
//!
//! Each item has one path: the crate root's, or that of the public module holding it
//! (`mergesim_types::bounds::Bound`, `mergesim_types::lanes::LaneRoad`).
#![warn(missing_docs)]

pub mod angle;
pub(crate) mod behaviour;
pub mod bounds;
pub(crate) mod error;
pub mod files;
pub(crate) mod grid;
pub mod lanes;
pub(crate) mod path;
pub mod percentile;
pub(crate) mod road;
pub(crate) mod vehicle;

pub use behaviour::{
    Behaviour, BehaviourError, Decision, DegradedMode, FallbackReason, Observation, OptimiserReport,
};
pub use error::InvalidParameter;
pub use grid::{GridSpec, MAX_GRID_CELLS};
pub use path::{PathPoint, SharedLocalPath, TimedWaypoint};
pub use road::{Lane, MERGE_SECTION_LENGTH_M, MergeRoad, ROAD_BOUNDS};
pub use vehicle::{Neighbour, VehicleId, VehicleShape, VehicleState, planning_brake_decel_mps2};
