//! The closed-loop merge simulation: the `World` (rapier physics, vehicles, planners, trackers),
//! the V2V bus, exact parry safety checks, metrics and the Rerun recording.
pub mod body_state;
pub mod config;
pub mod error;
pub mod idm;
pub mod metrics;
pub mod paper_metrics;
pub mod recording;
pub mod rng;
pub mod safety;
pub mod v2v;
pub mod world;

pub use config::{Driver, SimConfig, VehicleSpec, validate_vehicles};
pub use error::SimError;
pub use world::{PlannerStats, RunOptions, RunOutcome, TimeSeriesRow, World};
