//! The Intelligent Driver Model (IDM): a human-like car-following law for non-connected vehicles
//! in mixed traffic (Treiber, Hennecke & Helbing, "Congested traffic states in empirical
//! observations and microscopic simulations", Phys. Rev. E 62, 1805, 2000).
//!
//! ```text
//! a_IDM = a · [ 1 − (v / v₀)^δ − (s*(v, Δv) / s)² ]
//! s*(v, Δv) = s₀ + max(0, v·T + v·Δv / (2·√(a·b)))
//! ```
//!
//! with v the speed, v₀ the desired speed, s the bumper-to-bumper gap to the leader and
//! Δv = v − v_leader the approach rate. Without a leader the interaction term is dropped.
//!
//! Pure functions: no physics, no state. The world calls `find_leader` and
//! `idm_acceleration` at each planning tick of an IDM vehicle and turns the acceleration into
//! the speed profile of its lane-keeping path with `speed_after_distance`.

use serde::{Deserialize, Serialize};

use mergesim_types::bounds::{self, Bound};

use crate::error::SimError;

/// IDM parameters. Defaults: the original paper's highway set (Treiber et al. 2000, Table I),
/// except the desired speed, which is each vehicle's `target_speed_mps`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IdmParams {
    /// Maximum acceleration a (m/s²).
    pub max_accel_mps2: f64,
    /// Comfortable deceleration b (m/s²).
    pub comfortable_decel_mps2: f64,
    /// Safe time headway T (s).
    pub time_headway_s: f64,
    /// Minimum (jam) gap s₀ (m).
    pub min_gap_m: f64,
    /// Acceleration exponent δ.
    pub accel_exponent: f64,
    /// Physical braking limit: the IDM's output is clamped to −this (m/s²). The model itself
    /// is unbounded when the gap closes; a tire cannot brake harder than about μ·g.
    pub max_decel_mps2: f64,
    /// A vehicle is the leader when its centre lies within this lateral distance of the
    /// follower's centre (m): the follower's lane (half of 3.5 m) plus most of a car that has
    /// started to cut in.
    pub corridor_half_width_m: f64,
}

impl Default for IdmParams {
    fn default() -> Self {
        Self {
            max_accel_mps2: 0.73,
            comfortable_decel_mps2: 1.67,
            time_headway_s: 1.6,
            min_gap_m: 2.0,
            accel_exponent: 4.0,
            max_decel_mps2: 8.0,
            corridor_half_width_m: 2.5,
        }
    }
}

/// Allowed ranges of the IDM parameters (README "Limits").
pub const IDM_BOUNDS: &[Bound] = &[
    Bound::closed("max_accel_mps2", 0.01, 20.0, "m/s²"),
    Bound::closed("comfortable_decel_mps2", 0.01, 20.0, "m/s²"),
    Bound::closed("time_headway_s", 0.0, 10.0, "s"),
    Bound::closed("min_gap_m", 0.0, 50.0, "m"),
    Bound::closed("accel_exponent", 0.1, 20.0, ""),
    Bound::closed("max_decel_mps2", 0.1, 30.0, "m/s²"),
    Bound::closed("corridor_half_width_m", 0.1, 10.0, "m"),
];

impl IdmParams {
    /// Checks every field against [`IDM_BOUNDS`]; the error names it (`idm.<field>`).
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        bounds::check_all(
            "idm",
            IDM_BOUNDS,
            &[
                ("max_accel_mps2", self.max_accel_mps2),
                ("comfortable_decel_mps2", self.comfortable_decel_mps2),
                ("time_headway_s", self.time_headway_s),
                ("min_gap_m", self.min_gap_m),
                ("accel_exponent", self.accel_exponent),
                ("max_decel_mps2", self.max_decel_mps2),
                ("corridor_half_width_m", self.corridor_half_width_m),
            ],
        )?;
        if self.comfortable_decel_mps2 > self.max_decel_mps2 {
            return Err(SimError::invalid(
                "idm.comfortable_decel_mps2",
                self.comfortable_decel_mps2,
                format!(
                    "must not exceed idm.max_decel_mps2 = {} m/s²",
                    self.max_decel_mps2
                ),
            ));
        }
        Ok(())
    }
}

/// The vehicle ahead, as the follower sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Leader {
    /// Index of the leader in the slice given to [`find_leader`].
    pub index: usize,
    /// Bumper-to-bumper gap s (m); may be ≤ 0 when the bodies overlap longitudinally.
    pub gap_m: f64,
    /// Leader's speed (m/s).
    pub speed_mps: f64,
}

/// What [`find_leader`] needs to know of a vehicle, in a lane's frame: `x_m` the arc length s
/// along the lane, `y_m` the offset d across it (on the straight merge road, x and y up to a
/// constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RoadUser {
    /// Position of the centre (m).
    pub x_m: f64,
    /// Position of the centre (m).
    pub y_m: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
    /// Body length (m).
    pub length_m: f64,
}

/// Desired gap s*(v, Δv) (m).
pub fn desired_gap_m(params: &IdmParams, speed_mps: f64, approach_rate_mps: f64) -> f64 {
    let brake = speed_mps * approach_rate_mps
        / (2.0 * (params.max_accel_mps2 * params.comfortable_decel_mps2).sqrt());
    params.min_gap_m + (speed_mps * params.time_headway_s + brake).max(0.0)
}

/// IDM acceleration (m/s²), clamped to `[−max_decel_mps2, max_accel_mps2]`. Negative speeds
/// count as 0; a non-positive gap gives full braking.
pub(crate) fn idm_acceleration(
    params: &IdmParams,
    speed_mps: f64,
    desired_speed_mps: f64,
    leader: Option<&Leader>,
) -> f64 {
    let v = speed_mps.max(0.0);
    let v0 = desired_speed_mps.max(1e-3);
    let free = 1.0 - (v / v0).powf(params.accel_exponent);
    let interaction = match leader {
        None => 0.0,
        Some(l) if l.gap_m <= 0.0 => f64::INFINITY,
        Some(l) => (desired_gap_m(params, v, v - l.speed_mps) / l.gap_m).powi(2),
    };
    (params.max_accel_mps2 * (free - interaction))
        .clamp(-params.max_decel_mps2, params.max_accel_mps2)
}

/// The nearest vehicle ahead of `others[ego]` whose centre lies within the corridor.
pub(crate) fn find_leader(params: &IdmParams, others: &[RoadUser], ego: usize) -> Option<Leader> {
    let me = others.get(ego)?;
    others
        .iter()
        .enumerate()
        .filter(|(j, o)| {
            *j != ego && o.x_m > me.x_m && (o.y_m - me.y_m).abs() < params.corridor_half_width_m
        })
        .min_by(|(_, a), (_, b)| a.x_m.total_cmp(&b.x_m))
        .map(|(index, o)| Leader {
            index,
            gap_m: o.x_m - me.x_m - 0.5 * (o.length_m + me.length_m),
            speed_mps: o.speed_mps,
        })
}

/// Speed after `distance_m` at constant acceleration from `speed_mps` (v² = v₀² + 2·a·d),
/// 0 once the vehicle would have stopped.
pub(crate) fn speed_after_distance(speed_mps: f64, accel_mps2: f64, distance_m: f64) -> f64 {
    (speed_mps.max(0.0).powi(2) + 2.0 * accel_mps2 * distance_m.max(0.0))
        .max(0.0)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leader(gap_m: f64, speed_mps: f64) -> Leader {
        Leader {
            index: 0,
            gap_m,
            speed_mps,
        }
    }

    #[test]
    fn free_road_follows_the_closed_form() {
        let p = IdmParams::default();
        // Standing start: full acceleration a; at the desired speed: zero.
        assert_eq!(idm_acceleration(&p, 0.0, 20.0, None), p.max_accel_mps2);
        assert!(idm_acceleration(&p, 20.0, 20.0, None).abs() < 1e-12);
        // a(1 − (v/v₀)⁴) at half the desired speed: a·15/16.
        let a = idm_acceleration(&p, 10.0, 20.0, None);
        assert!((a - p.max_accel_mps2 * 15.0 / 16.0).abs() < 1e-12, "{a}");
    }

    #[test]
    fn equilibrium_gap_gives_zero_acceleration() {
        // Steady following: a_IDM = 0 with Δv = 0 solved for the gap gives
        // s_e(v) = (s₀ + v·T) / √(1 − (v/v₀)^δ) (Treiber & Kesting, Traffic Flow Dynamics, §11.3).
        let p = IdmParams::default();
        for v in [5.0, 12.0, 18.0] {
            let s_e = (p.min_gap_m + v * p.time_headway_s)
                / (1.0 - (v / 20.0f64).powf(p.accel_exponent)).sqrt();
            let a = idm_acceleration(&p, v, 20.0, Some(&leader(s_e, v)));
            assert!(a.abs() < 1e-12, "v = {v}: {a}");
            // Closer than equilibrium: brake; farther: accelerate.
            assert!(idm_acceleration(&p, v, 20.0, Some(&leader(0.9 * s_e, v))) < 0.0);
            assert!(idm_acceleration(&p, v, 20.0, Some(&leader(1.1 * s_e, v))) > 0.0);
        }
        // Jam: standing at the minimum gap behind a standing leader.
        assert!(idm_acceleration(&p, 0.0, 20.0, Some(&leader(p.min_gap_m, 0.0))).abs() < 1e-12);
    }

    #[test]
    fn approaching_a_stopped_car_at_the_kinematic_distance_brakes_at_b() {
        // With s₀ = T = 0, closing on a standing car at v from s = v²/(2b) (where braking at b
        // stops exactly): s* = v²/(2√(ab)), so a·(s*/s)² = b and a_IDM = a(1 − (v/v₀)^δ) − b.
        let p = IdmParams {
            min_gap_m: 0.0,
            time_headway_s: 0.0,
            ..IdmParams::default()
        };
        let (v, v0) = (10.0, 30.0);
        let s = v * v / (2.0 * p.comfortable_decel_mps2);
        let a = idm_acceleration(&p, v, v0, Some(&leader(s, 0.0)));
        let expected = p.max_accel_mps2 * (1.0 - (v / v0).powi(4)) - p.comfortable_decel_mps2;
        assert!((a - expected).abs() < 1e-12, "{a} vs {expected}");
    }

    #[test]
    fn braking_is_bounded_and_overlap_brakes_fully() {
        let p = IdmParams::default();
        assert_eq!(
            idm_acceleration(&p, 20.0, 20.0, Some(&leader(0.5, 0.0))),
            -p.max_decel_mps2
        );
        assert_eq!(
            idm_acceleration(&p, 5.0, 20.0, Some(&leader(-1.0, 5.0))),
            -p.max_decel_mps2
        );
    }

    #[test]
    fn leader_is_the_nearest_vehicle_ahead_in_the_corridor() {
        let p = IdmParams::default();
        let car = |x_m: f64, y_m: f64, speed_mps: f64| RoadUser {
            x_m,
            y_m,
            speed_mps,
            length_m: 4.0,
        };
        let users = [
            car(0.0, 5.25, 15.0),   // the follower, upper lane
            car(60.0, 5.25, 14.0),  // ahead, same lane
            car(30.0, 1.75, 20.0),  // nearer, but in the other lane
            car(-10.0, 5.25, 16.0), // behind
            car(40.0, 3.5, 18.0),   // cutting in across the divider
        ];
        let l = find_leader(&p, &users, 0).unwrap();
        assert_eq!(l.index, 4);
        assert!((l.gap_m - 36.0).abs() < 1e-12);
        assert_eq!(l.speed_mps, 18.0);
        assert_eq!(find_leader(&p, &users[..4], 0).unwrap().index, 1);
        assert!(find_leader(&p, &users, 1).is_none());
        assert!(find_leader(&p, &users, 9).is_none());
    }

    #[test]
    fn speed_after_distance_is_constant_acceleration_kinematics() {
        assert!((speed_after_distance(10.0, 1.0, 50.0) - 200f64.sqrt()).abs() < 1e-12);
        assert_eq!(speed_after_distance(10.0, -2.0, 100.0), 0.0);
        assert!((speed_after_distance(10.0, -2.0, 9.0) - 64f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = IdmParams {
            time_headway_s: -1.0,
            ..IdmParams::default()
        };
        let err = p.validate().unwrap_err().to_string();
        assert!(
            err.contains("idm.time_headway_s") && err.contains("-1"),
            "{err}"
        );
        IdmParams::default().validate().unwrap();
    }
}
