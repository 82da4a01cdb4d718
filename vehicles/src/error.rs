//! Typed errors of the vehicle crate.

use thiserror::Error;

/// Everything that can go wrong when building or driving a vehicle. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum VehicleError {
    /// A parameter or input is outside its allowed range (or not finite).
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Dotted name of the parameter, e.g. `vehicle.mass_kg`.
        name: String,
        /// The offending value.
        value: f64,
        /// What the allowed range is.
        reason: String,
    },
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
}

impl VehicleError {
    /// Shorthand for [`VehicleError::InvalidParameter`].
    pub(crate) fn invalid(name: impl Into<String>, value: f64, reason: impl Into<String>) -> Self {
        Self::InvalidParameter {
            name: name.into(),
            value,
            reason: reason.into(),
        }
    }
}
