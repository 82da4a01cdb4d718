//! Typed errors of the planner.

use thiserror::Error;

pub(crate) use mergesim_types::InvalidParameter;

/// Everything that can go wrong in the planner. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PlannerError {
    /// A parameter is out of its allowed range.
    #[error(transparent)]
    InvalidParameter(#[from] InvalidParameter),
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
    /// The road's lanes are inconsistent (the error names the lane and what is wrong).
    #[error(transparent)]
    Road(#[from] mergesim_types::lanes::LaneError),
    /// The convex solver did not reach a usable solution.
    #[error("solver failed in {problem}: status {status}")]
    SolverFailed {
        /// Which problem (`cubic_fit`, `speed_optimisation`).
        problem: String,
        /// Clarabel's status, as text.
        status: String,
    },
}

impl PlannerError {
    /// Shorthand for [`PlannerError::InvalidParameter`].
    pub(crate) fn invalid(name: impl Into<String>, value: f64, reason: impl Into<String>) -> Self {
        Self::InvalidParameter(InvalidParameter::new(name, value, reason))
    }

    /// The parameter it names, if it is about one.
    pub fn invalid_parameter(&self) -> Option<&InvalidParameter> {
        match self {
            Self::InvalidParameter(p) => Some(p),
            _ => None,
        }
    }
}
