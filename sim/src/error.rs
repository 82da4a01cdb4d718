//! Typed errors of the simulator.

use thiserror::Error;

/// Everything that can stop a simulation. Never a panic.
#[derive(Debug, Error)]
pub enum SimError {
    /// A parameter is out of range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Dotted name, e.g. `v2v.drop_probability`.
        name: String,
        /// The offending value.
        value: f64,
        /// The allowed range.
        reason: String,
    },
    /// Something about the scenario's vehicles is inconsistent (duplicate ids, ...).
    #[error("invalid scenario: {0}")]
    InvalidScenario(String),
    /// The vehicle model refused its parameters or state.
    #[error(transparent)]
    Vehicle(#[from] vehicles::VehicleError),
    /// The planner refused its input.
    #[error("planner of vehicle {vehicle}: {source}")]
    Planner {
        /// The vehicle's name.
        vehicle: String,
        /// What the planner said.
        source: planner::PlannerError,
    },
    /// The physics diverged (non-finite or runaway state).
    #[error("simulation diverged at t = {t_s} s: {what}")]
    Diverged {
        /// Time of detection.
        t_s: f64,
        /// What was wrong.
        what: String,
    },
    /// Writing an output failed.
    #[error("recording: {0}")]
    Recording(String),
}
