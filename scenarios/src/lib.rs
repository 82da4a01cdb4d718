//! Scenario definitions: the TOML format, validation, randomisation and the built-in scenarios.
//!
//! A scenario is a `[sim]` table (a [`sim::config::SimConfig`]), a list of `[[vehicles]]`
//! ([`sim::config::VehicleSpec`]) and an optional `[randomise]` table
//! ([`randomisation::Randomisation`]) of the ranges a Monte-Carlo sweep draws instances from.
//! Unknown keys are rejected; every number is range-checked, for the nominal values and for
//! every instance the ranges allow; errors name the file, the line and the field.
//!
//! # Public API
//! - [`scenario::Scenario`]: a scenario read from TOML ([`scenario::ScenarioSource`] says where
//!   from), validated, with its errors [`scenario::ScenarioError`] (naming the file, line and
//!   field, [`source_location`]).
//! - [`randomisation::Randomisation`] and [`randomisation::VehicleRandomisation`]: the ranges a
//!   sweep draws instances from, as [`Distribution`]s ([`NormalOffset`]).
//! - [`traffic::TrafficStream`]: the `[traffic]` tables, vehicles generated per instance from
//!   traffic flows (shifted-exponential headways, placed at t = 0).
//! - The built-in scenarios ([`builtin`]) and generated platoons ([`platoon`]); the scenario
//!   module itself, [`scenario`], and the randomisation module, [`randomisation`].
//!
//! Each item has one path: a public module holding more than what the crate root names is
//! the path of its items (`scenarios::scenario::Scenario`).
#![warn(missing_docs)]

pub mod builtin;
pub(crate) mod commonroad;
mod commonroad_toml;
pub(crate) mod distribution;
mod opendrive_source;
pub(crate) mod oriented_box;
pub mod platoon;
pub mod randomisation;
pub mod scenario;
pub mod source_location;
pub mod traffic;

pub use distribution::{Distribution, NormalOffset};
