//! The one error for a parameter out of range, shared by every crate (each crate's error enum
//! wraps it, so the offending field's dotted name survives up to the scenario loader, which turns
//! it into a file, a line and a field).

use thiserror::Error;

/// A parameter or input outside its allowed range (or not finite).
#[derive(Debug, Error, Clone, PartialEq)]
#[error("invalid parameter {name} = {value}: {reason}")]
pub struct InvalidParameter {
    /// Dotted name of the parameter, e.g. `road.lane_width_m` or `planner.step_time_s`.
    pub name: String,
    /// The offending value.
    pub value: f64,
    /// What the allowed range is.
    pub reason: String,
}

impl InvalidParameter {
    /// An error naming `name`, its `value` and the allowed range.
    pub fn new(name: impl Into<String>, value: f64, reason: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            value,
            reason: reason.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_names_field_value_and_range() {
        let e = InvalidParameter::new("road.lane_width_m", 9.0, "must lie in [2, 6] m");
        assert_eq!(
            e.to_string(),
            "invalid parameter road.lane_width_m = 9: must lie in [2, 6] m"
        );
    }
}
