//! The one angle wrap of the project.
//!
//! Every heading difference (the tracker's heading error, the planner's turn and heading caps and
//! lane-relative headings, the recorded traffic's heading interpolation, the metrics' largest
//! |yaw|, the lane road's successor test) is wrapped here, by one rule:
//! - an angle already in [−π, π) is returned unchanged, bit for bit;
//! - any other finite angle becomes `(a + π).rem_euclid(2π) − π`, forced into [−π, π) where
//!   rounding would give π.
//!
//! The first rule keeps the common case exact: a small heading error is not rounded through an
//! addition and subtraction of π.

use std::f64::consts::{PI, TAU};

/// Wraps an angle (rad) to [−π, π).
///
/// An angle already in [−π, π) is returned unchanged, bit for bit. Non-finite input gives NaN
/// (callers that need finite angles check for it).
pub fn wrap_angle_rad(angle_rad: f64) -> f64 {
    if (-PI..PI).contains(&angle_rad) {
        return angle_rad;
    }
    let wrapped = (angle_rad + PI).rem_euclid(TAU) - PI;
    // `rem_euclid` may round up to 2π itself, which would give π.
    if wrapped >= PI { -PI } else { wrapped }
}

/// The unsigned angle between two directions (rad), in [0, π].
pub fn angle_between_rad(a_rad: f64, b_rad: f64) -> f64 {
    wrap_angle_rad(a_rad - b_rad).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_range_angles_are_returned_bit_for_bit() {
        for a in [
            -PI,
            -3.0,
            -1e-300,
            -0.0,
            0.0,
            1e-17,
            0.1 + 0.2,
            3.0,
            PI - 1e-15,
        ] {
            assert_eq!(wrap_angle_rad(a).to_bits(), a.to_bits(), "{a}");
        }
    }

    #[test]
    fn out_of_range_angles_land_in_the_half_open_interval() {
        assert_eq!(wrap_angle_rad(PI), -PI);
        assert!((wrap_angle_rad(3.0 * PI) + PI).abs() < 1e-12);
        assert!((wrap_angle_rad(TAU + 0.3) - 0.3).abs() < 1e-12);
        assert!((wrap_angle_rad(-TAU - 0.3) + 0.3).abs() < 1e-12);
        assert!((wrap_angle_rad(-PI - 0.5) - (PI - 0.5)).abs() < 1e-12);
        // Just below −π: rem_euclid rounds to 2π; the result must still be below π.
        let just_below = -PI - f64::EPSILON;
        let w = wrap_angle_rad(just_below);
        assert!((-PI..PI).contains(&w), "{w}");
        for k in -1000..1000 {
            let a = 0.37 * f64::from(k);
            let w = wrap_angle_rad(a);
            assert!((-PI..PI).contains(&w), "{a} -> {w}");
            let turns = (a - w) / TAU;
            assert!((turns - turns.round()).abs() < 1e-9, "{a} -> {w}");
        }
    }

    #[test]
    fn non_finite_angles_give_nan() {
        assert!(wrap_angle_rad(f64::NAN).is_nan());
        assert!(wrap_angle_rad(f64::INFINITY).is_nan());
    }

    #[test]
    fn angle_between_is_symmetric_and_at_most_pi() {
        assert!((angle_between_rad(0.1, TAU - 0.1) - 0.2).abs() < 1e-12);
        assert_eq!(angle_between_rad(0.0, PI), PI);
        assert_eq!(angle_between_rad(0.3, 0.1), angle_between_rad(0.1, 0.3));
    }
}
