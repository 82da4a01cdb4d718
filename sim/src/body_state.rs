//! The plain kinematic state of one vehicle body, as the safety monitor and the recorder see it.
//!
//! Deliberately independent of the vehicle model: the world loop copies the rapier chassis pose
//! and velocity into this struct, so safety checks and logging can be tested on synthetic data.

use serde::{Deserialize, Serialize};

use mergesim_types::VehicleId;

/// Pose, velocity and footprint of a vehicle body at one instant (world frame, SI units).
///
/// The body is a box of `length_m × width_m × height_m` resting on the road plane (Z = 0),
/// centred at (`x_m`, `y_m`) and rotated by `yaw_rad` about +Z.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyState {
    /// Vehicle id (the deterministic visiting order).
    pub id: VehicleId,
    /// Centre of the box along the road (m).
    pub x_m: f64,
    /// Centre of the box across the road (m).
    pub y_m: f64,
    /// Heading of the body x axis, counter-clockwise from +X (rad).
    pub yaw_rad: f64,
    /// World-frame velocity along X (m/s).
    pub vx_mps: f64,
    /// World-frame velocity along Y (m/s).
    pub vy_mps: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate_radps: f64,
    /// Body length (m).
    pub length_m: f64,
    /// Body width (m).
    pub width_m: f64,
    /// Body height (m).
    pub height_m: f64,
}

impl BodyState {
    /// Radius of the circle around the centre that contains the whole footprint (half diagonal).
    pub(crate) fn bounding_radius_m(&self) -> f64 {
        0.5 * self.length_m.hypot(self.width_m)
    }

    /// Half the footprint's extent along the unit vector `u` (m): half-length · |u·heading| +
    /// half-width · |u·left|. The footprint's projection on `u` is its centre's ± this.
    pub(crate) fn half_extent_along_m(&self, u: [f64; 2]) -> f64 {
        let (sin_yaw, cos_yaw) = self.yaw_rad.sin_cos();
        0.5 * self.length_m * (u[0] * cos_yaw + u[1] * sin_yaw).abs()
            + 0.5 * self.width_m * (-u[0] * sin_yaw + u[1] * cos_yaw).abs()
    }

    /// A standing box for tests: `id` at `[x_m, y_m, yaw_rad]` with `[length_m, width_m,
    /// height_m]`.
    #[cfg(test)]
    pub(crate) fn standing(id: VehicleId, pose: [f64; 3], size_m: [f64; 3]) -> Self {
        Self {
            id,
            x_m: pose[0],
            y_m: pose[1],
            yaw_rad: pose[2],
            vx_mps: 0.0,
            vy_mps: 0.0,
            yaw_rate_radps: 0.0,
            length_m: size_m[0],
            width_m: size_m[1],
            height_m: size_m[2],
        }
    }

    /// Speed over ground (m/s).
    pub(crate) fn speed_mps(&self) -> f64 {
        self.vx_mps.hypot(self.vy_mps)
    }

    /// The first field that is not finite, or a dimension that is not strictly positive,
    /// as `(field name, value)`; `None` when the state is usable.
    pub(crate) fn first_invalid_field(&self) -> Option<(&'static str, f64)> {
        let finite = [
            ("x_m", self.x_m),
            ("y_m", self.y_m),
            ("yaw_rad", self.yaw_rad),
            ("vx_mps", self.vx_mps),
            ("vy_mps", self.vy_mps),
            ("yaw_rate_radps", self.yaw_rate_radps),
        ];
        if let Some(bad) = finite.into_iter().find(|(_, v)| !v.is_finite()) {
            return Some(bad);
        }
        let dimensions = [
            ("length_m", self.length_m),
            ("width_m", self.width_m),
            ("height_m", self.height_m),
        ];
        dimensions
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> BodyState {
        BodyState {
            id: 0,
            x_m: 1.0,
            y_m: 2.0,
            yaw_rad: 0.1,
            vx_mps: 3.0,
            vy_mps: 4.0,
            yaw_rate_radps: 0.0,
            length_m: 4.0,
            width_m: 3.0,
            height_m: 1.5,
        }
    }

    #[test]
    fn bounding_radius_is_half_diagonal_and_speed_is_norm() {
        let b = body();
        assert!((b.bounding_radius_m() - 2.5).abs() < 1e-12);
        assert!((b.speed_mps() - 5.0).abs() < 1e-12);
    }

    #[test]
    fn invalid_fields_are_named() {
        assert_eq!(body().first_invalid_field(), None);
        let nan = BodyState {
            vy_mps: f64::NAN,
            ..body()
        };
        assert_eq!(nan.first_invalid_field().map(|(n, _)| n), Some("vy_mps"));
        let flat = BodyState {
            width_m: 0.0,
            ..body()
        };
        assert_eq!(flat.first_invalid_field(), Some(("width_m", 0.0)));
    }
}
