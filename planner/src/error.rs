//! Typed errors of the planner.

use thiserror::Error;

/// Everything that can go wrong in the planner. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PlannerError {
    /// A parameter is out of its allowed range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Dotted name of the parameter, e.g. `road.lane_width_m`.
        name: String,
        /// The offending value.
        value: f64,
        /// What the allowed range is.
        reason: String,
    },
    /// A state or intermediate value is NaN or infinite.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Where it was found.
        what: String,
    },
    /// A name (e.g. of a planner) that is not one of the valid ones.
    #[error("unknown {what} '{given}'; valid: {valid}")]
    UnknownName {
        /// What was being named (`planner`).
        what: String,
        /// The name given.
        given: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// The convex solver did not reach a usable solution.
    #[error("solver failed in {problem}: status {status}")]
    SolverFailed {
        /// Which problem (`cubic_fit`, `speed_optimisation`).
        problem: String,
        /// Clarabel's status, as text.
        status: String,
    },
}
