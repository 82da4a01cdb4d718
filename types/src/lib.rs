//! Plain data shared by mergesim's crates: the merge road's geometry, roads made of lanes (the
//! curvilinear lane frame, [`lanes`]), a vehicle's state and
//! shape, path points and the shared local paths exchanged over V2V, a sampling grid, and the one
//! typed error for a parameter out of range.
//!
//! No physics, no optimiser, no logging: the planner, the vehicle model and the simulator all
//! speak these types, and depend on nothing else to do so.
#![warn(missing_docs)]

pub mod behaviour;
pub mod bounds;
pub mod error;
pub mod files;
pub mod grid;
pub mod lanes;
pub mod path;
pub mod percentile;
pub mod road;
pub mod vehicle;

pub use behaviour::{
    Behaviour, BehaviourError, Decision, DegradedMode, FallbackReason, Observation,
    OptimiserReport,
};
pub use bounds::Bound;
pub use error::InvalidParameter;
pub use grid::{GridSpec, MAX_GRID_CELLS};
pub use path::{PathPoint, SharedLocalPath, TimedWaypoint};
pub use road::{Lane, MergeRoad};
pub use vehicle::{Neighbour, VehicleId, VehicleShape, VehicleState};
