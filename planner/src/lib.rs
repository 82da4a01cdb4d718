//! Pure planning library of mergesim: road geometry, potential fields (paper Eqs. 1–7),
//! constrained cubic fit (Eqs. 8–9) and interactive speed optimisation (Eq. 10).
//!
//! No physics engine, no logging backend: plain state in, plan out, so it can run on a car.
//! `planner/README.md` maps each equation of the paper to the function implementing it and
//! lists every reading of a typo or unit problem.
#![warn(missing_docs)]

pub mod attractive_field;
pub mod behaviour;
mod clarabel_setup;
pub mod cubic_fit;
pub mod derived_params;
pub mod error;
pub mod fallback;
pub mod field_params;
pub mod following;
pub mod lane_frame;
mod lane_road_edges;
pub mod lane_road_field;
mod lane_road_frames;
pub mod local_path;
pub mod min_distance;
pub mod obstacle_field;
pub mod others;
pub mod parameter_set;
pub mod params;
pub mod params_tables;
pub mod planners;
pub mod polyline;
pub mod potential_field;
pub mod prediction;
pub mod request;
pub mod road;
pub mod road_field;
pub mod speed_optimisation;
pub mod speed_profile;
pub mod stop_and_go;
pub mod types;

pub use error::PlannerError;
pub use following::V2vLossFallback;
pub use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};
pub use parameter_set::ParameterSet;
pub use params::{PlannerParams, SlpReading};
pub use planners::{PfPlanner, PlanRequest, PlanStats, PlannerKind};
pub use potential_field::{GridSpec, PotentialField};
pub use road::{Lane, MergeRoad};
pub use speed_optimisation::SpeedProgram;
pub use speed_profile::SpeedProfile;
pub use types::*;

/// The README's examples, compiled and run as doc tests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
