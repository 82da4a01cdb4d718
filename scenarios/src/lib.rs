//! Scenario definitions: the TOML format, validation and the built-in scenarios.
//!
//! A scenario is a `[sim]` table (a [`sim::SimConfig`]) and a list of `[[vehicles]]`
//! ([`sim::VehicleSpec`]). Unknown keys are rejected; every number is range-checked.

pub mod builtin;
pub mod scenario;

pub use scenario::{Scenario, ScenarioError};
