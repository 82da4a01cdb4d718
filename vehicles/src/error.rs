//! Typed errors of the vehicle crate.

use thiserror::Error;

pub(crate) use mergesim_types::InvalidParameter;

/// Everything that can go wrong when building or driving a vehicle. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum VehicleError {
    /// A parameter or input is outside its allowed range (or not finite).
    #[error(transparent)]
    InvalidParameter(#[from] InvalidParameter),
    /// A vehicle preset name that does not exist.
    #[error("unknown vehicle preset {name:?}; valid presets: {valid}")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// Comma-separated list of valid names.
        valid: String,
    },
    /// No road surface below a spawn point.
    #[error("no road surface below spawn point (x = {x_m} m, y = {y_m} m)")]
    NoGround {
        /// Spawn position (m).
        x_m: f64,
        /// Spawn position (m).
        y_m: f64,
    },
    /// The chassis rigid body is no longer in the physics world.
    #[error("vehicle chassis body is missing from the physics world")]
    MissingBody,
    /// The car's figures in CommonRoad's terms are unusable by its models.
    #[error(transparent)]
    CommonRoadParams(#[from] crate::commonroad_models::CommonRoadParamsError),
}

impl VehicleError {
    /// Shorthand for [`VehicleError::InvalidParameter`].
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
