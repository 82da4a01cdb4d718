//! Which CommonRoad model moves a car, and the step sizes it is integrated with.

use serde::{Deserialize, Serialize};

use crate::error::VehicleError;

/// Which of CommonRoad's models moves the car.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CommonRoadModel {
    /// Kinematic single track (no tyres, no sideslip of the rear axle).
    Ks,
    /// Single track with linear tyres (no saturation: valid while |a_y| ≲ 0.4·μ·g).
    St,
    /// Single-track drift model: Magic-Formula tyres that saturate at μ, wheel spin.
    Std,
}

impl CommonRoadModel {
    /// Every model, in the order of their fidelity.
    pub const ALL: [CommonRoadModel; 3] = [Self::Ks, Self::St, Self::Std];

    /// The registered name: `ks`, `st` or `std`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ks => "ks",
            Self::St => "st",
            Self::Std => "std",
        }
    }

    /// The model of a registered name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// Step sizes of the CommonRoad vehicles' RK4 integration (s). Each physics step is cut into
/// the fewest equal sub-steps no longer than the model's limit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CommonRoadIntegration {
    /// Longest sub-step of the ks model (s).
    pub ks_max_substep_s: f64,
    /// Longest sub-step of the st model (s): its sideslip mode, λ ≈ −215 s⁻¹·(1 m/s)/v for the
    /// BMW, is stable with 1 ms down to its switch to the kinematic model at 0.1 m/s.
    pub st_max_substep_s: f64,
    /// Longest sub-step of the std model at or above `std_slow_speed_mps` (s).
    pub std_max_substep_s: f64,
    /// Longest sub-step of the std model below `std_slow_speed_mps` (s): its wheel-spin modes
    /// stiffen as 1/(wheel ground speed).
    pub std_slow_max_substep_s: f64,
    /// Speed below which the std model takes the slow sub-step (m/s).
    pub std_slow_speed_mps: f64,
}

impl Default for CommonRoadIntegration {
    fn default() -> Self {
        Self {
            ks_max_substep_s: 0.01,
            st_max_substep_s: 1e-3,
            std_max_substep_s: 1e-3,
            std_slow_max_substep_s: 1e-4,
            std_slow_speed_mps: 5.0,
        }
    }
}

impl CommonRoadIntegration {
    /// Checks that every step is finite and > 0 and the speed finite and ≥ 0.
    pub fn validate(&self) -> Result<(), VehicleError> {
        for (name, value) in [
            ("ks_max_substep_s", self.ks_max_substep_s),
            ("st_max_substep_s", self.st_max_substep_s),
            ("std_max_substep_s", self.std_max_substep_s),
            ("std_slow_max_substep_s", self.std_slow_max_substep_s),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(VehicleError::invalid(name, value, "must be finite and > 0"));
            }
        }
        let v = self.std_slow_speed_mps;
        if !(v.is_finite() && v >= 0.0) {
            return Err(VehicleError::invalid(
                "std_slow_speed_mps",
                v,
                "must be finite and >= 0",
            ));
        }
        Ok(())
    }
}
