//! Pure planning library of mergesim: road geometry, potential fields (paper Eqs. 1–7),
//! constrained cubic fit (Eqs. 8–9) and interactive speed optimisation (Eq. 10).
//!
//! No physics engine, no logging backend: plain state in, plan out, so it can run on a car.
//! `planner/README.md` maps each equation of the paper to the function implementing it and
//! lists every reading of a typo or unit problem.
//!
//! # Public API
//! - The planner: [`PfPlanner`] (a [`Behaviour`](mergesim_types::Behaviour)) of a
//!   [`PlannerKind`], built from [`params::PlannerParams`] (or a named [`ParameterSet`]); one
//!   planning step takes a [`PlanRequest`] and gives a [`Plan`] (or a [`PlannerError`]), with
//!   [`PlanStats`] and, when it fell back, a
//!   [`FallbackReason`](mergesim_types::FallbackReason).
//! - Its parameters: [`params`] ([`params::PlannerParams`], [`params::SlpReading`]),
//!   [`speed_optimisation::SpeedProgram`], [`following::V2vLossFallback`] and the tables of a
//!   scenario's `[planner.*]` keys, [`params_tables`].
//! - The fields and steps, usable on their own: [`potential_field::PotentialField`] on a
//!   [`GridSpec`](mergesim_types::GridSpec),
//!   [`attractive_field`], [`obstacle_field`], [`road_field`], [`lane_road_field`],
//!   [`lane_frame`], [`local_path`], [`cubic_fit`], [`speed_optimisation`],
//!   [`speed_profile::SpeedProfile`], [`fallback`], [`following`] and [`others`].
//! - The plain data it speaks (vehicle state and shape, path points, shared local paths, the
//!   merge road) is [`mergesim_types`]': spelled `mergesim_types::VehicleState` and so on (the
//!   planner does not re-export it).
//!
//! Each item has one path: a module is public when it holds more than what the crate root
//! names, and then its items are reached through it (`planner::params::PlannerParams`).
#![warn(missing_docs)]

pub mod attractive_field;
pub(crate) mod behaviour;
mod clarabel_setup;
pub mod cubic_fit;
pub mod derived_params;
mod error;
pub mod fallback;
pub(crate) mod field_params;
pub mod following;
pub mod lane_frame;
mod lane_road_edges;
pub mod lane_road_field;
mod lane_road_frames;
pub mod local_path;
pub(crate) mod min_distance;
pub mod obstacle_field;
pub mod others;
pub(crate) mod parameter_set;
pub mod params;
pub mod params_tables;
mod plan;
mod planner_kind;
pub(crate) mod planners;
pub mod polyline;
pub mod potential_field;
pub(crate) mod prediction;
pub(crate) mod request;
pub mod road_field;
pub mod sequencing;
pub mod speed_optimisation;
pub mod speed_profile;
pub(crate) mod stop_and_go;

pub use error::PlannerError;
pub use parameter_set::ParameterSet;
pub use plan::Plan;
pub use planner_kind::PlannerKind;
pub use planners::{PfPlanner, PlanStats};
pub use request::PlanRequest;

/// The README's examples, compiled and run as doc tests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
