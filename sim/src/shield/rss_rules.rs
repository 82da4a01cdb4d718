//! The rules of Responsibility-Sensitive Safety (Shalev-Shwartz, Shammah & Shashua, "On a
//! Formal Model of Safe and Scalable Self-driving Cars", arXiv:1708.06374, 2017) for two cars
//! driving the same way: the safe longitudinal distance (their Definition 1), the safe lateral
//! distance (Definition 7), the dangerous situation (both distances unsafe) and which proper
//! response the blame time calls for. Pure functions of the cars' speeds and gaps.
//!
//! Gaps are between the bodies: a longitudinal gap is bumper to bumper, a lateral gap side to
//! side; a negative gap means the extents overlap in that direction.

use serde::{Deserialize, Serialize};

use mergesim_types::bounds::{self, Bound};

use crate::error::SimError;

/// RSS's parameters (`[sim.rss]`). Defaults: the starting values of Intel's open-source RSS
/// library (ad-rss-lib, "Parameter Discussion"): a response time of 1 s for the shielded car
/// and 2 s for every other (assumed human), 3.5 m/s² of acceleration, braking between 4 and
/// 8 m/s², 0.2 m/s² of lateral acceleration, 0.8 m/s² of lateral braking, 0.1 m of lateral
/// fluctuation margin.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RssParams {
    /// Response time ρ of the shielded car (s).
    pub response_time_s: f64,
    /// Response time ρ assumed for every other car (s).
    pub other_response_time_s: f64,
    /// Largest longitudinal acceleration during a response time, a_max,accel (m/s²).
    pub accel_max_mps2: f64,
    /// Least braking the rear car applies after its response time, a_min,brake (m/s²).
    pub brake_min_mps2: f64,
    /// Hardest braking the front car may apply, a_max,brake (m/s²).
    pub brake_max_mps2: f64,
    /// Largest lateral acceleration during a response time, a^lat_max,accel (m/s²).
    pub lat_accel_max_mps2: f64,
    /// Least lateral braking after a response time, a^lat_min,brake (m/s²).
    pub lat_brake_min_mps2: f64,
    /// Lateral fluctuation margin μ (m).
    pub lat_margin_m: f64,
}

impl Default for RssParams {
    fn default() -> Self {
        Self {
            response_time_s: 1.0,
            other_response_time_s: 2.0,
            accel_max_mps2: 3.5,
            brake_min_mps2: 4.0,
            brake_max_mps2: 8.0,
            lat_accel_max_mps2: 0.2,
            lat_brake_min_mps2: 0.8,
            lat_margin_m: 0.1,
        }
    }
}

/// Allowed ranges of the RSS parameters (README "Limits").
pub const RSS_BOUNDS: &[Bound] = &[
    Bound::closed("response_time_s", 0.0, 10.0, "s"),
    Bound::closed("other_response_time_s", 0.0, 10.0, "s"),
    Bound::closed("accel_max_mps2", 0.0, 30.0, "m/s²"),
    Bound::above("brake_min_mps2", 0.0, 30.0, "m/s²"),
    Bound::above("brake_max_mps2", 0.0, 30.0, "m/s²"),
    Bound::closed("lat_accel_max_mps2", 0.0, 30.0, "m/s²"),
    Bound::above("lat_brake_min_mps2", 0.0, 30.0, "m/s²"),
    Bound::closed("lat_margin_m", 0.0, 10.0, "m"),
];

impl RssParams {
    /// Whether every field has its default value.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field against [`RSS_BOUNDS`], and that the front car's hardest braking is
    /// at least the rear car's least; the error names the field (`rss.<field>`).
    pub fn validate(&self) -> Result<(), SimError> {
        bounds::check_all(
            "rss",
            RSS_BOUNDS,
            &[
                ("response_time_s", self.response_time_s),
                ("other_response_time_s", self.other_response_time_s),
                ("accel_max_mps2", self.accel_max_mps2),
                ("brake_min_mps2", self.brake_min_mps2),
                ("brake_max_mps2", self.brake_max_mps2),
                ("lat_accel_max_mps2", self.lat_accel_max_mps2),
                ("lat_brake_min_mps2", self.lat_brake_min_mps2),
                ("lat_margin_m", self.lat_margin_m),
            ],
        )?;
        if self.brake_max_mps2 < self.brake_min_mps2 {
            return Err(SimError::invalid(
                "rss.brake_max_mps2",
                self.brake_max_mps2,
                format!(
                    "must be at least rss.brake_min_mps2 = {} m/s²",
                    self.brake_min_mps2
                ),
            ));
        }
        Ok(())
    }
}

/// RSS Definition 1: the least safe bumper-to-bumper gap (m) behind a front car driving at
/// `front_speed_mps`, for a rear car at `rear_speed_mps` with response time `rear_response_s`:
///
/// ```text
/// d_min = [ v_r ρ + ½ a_max,accel ρ² + (v_r + ρ a_max,accel)² / (2 a_min,brake)
///           − v_f² / (2 a_max,brake) ]₊
/// ```
///
/// Speeds below 0 (driving backwards) are taken as 0.
pub fn safe_longitudinal_gap_m(
    rear_speed_mps: f64,
    front_speed_mps: f64,
    rear_response_s: f64,
    p: &RssParams,
) -> f64 {
    let (v_r, v_f, rho) = (
        rear_speed_mps.max(0.0),
        front_speed_mps.max(0.0),
        rear_response_s,
    );
    let after_response_mps = v_r + rho * p.accel_max_mps2;
    let d = v_r * rho
        + 0.5 * p.accel_max_mps2 * rho * rho
        + after_response_mps * after_response_mps / (2.0 * p.brake_min_mps2)
        - v_f * v_f / (2.0 * p.brake_max_mps2);
    d.max(0.0)
}

/// How far (m) a car closes in laterally under RSS's worst case: from a lateral speed of
/// `toward_mps` toward the other car it accelerates toward it at a^lat_max,accel for its
/// response time `response_s`, then brakes its lateral speed to zero at a^lat_min,brake.
/// Negative when it ends up farther away. (Definition 7 squares the speed after the response
/// time, which assumes the car still moves toward the other; the sign is kept here, so a car
/// that is still moving away then brakes farther away.)
fn lateral_approach_m(toward_mps: f64, response_s: f64, p: &RssParams) -> f64 {
    let after_response_mps = toward_mps + response_s * p.lat_accel_max_mps2;
    toward_mps * response_s
        + 0.5 * p.lat_accel_max_mps2 * response_s * response_s
        + after_response_mps * after_response_mps.abs() / (2.0 * p.lat_brake_min_mps2)
}

/// RSS Definition 7: the least safe side-to-side gap (m) between a car on the left and a car
/// on the right, from each car's lateral speed toward the other (m/s, positive when closing)
/// and response time:
///
/// ```text
/// d_min = μ + [ approach(left) + approach(right) ]₊
/// approach(v, ρ) = v ρ + ½ a^lat_max,accel ρ² + (v + ρ a^lat_max,accel)² / (2 a^lat_min,brake)
/// ```
pub fn safe_lateral_gap_m(
    left_toward_mps: f64,
    left_response_s: f64,
    right_toward_mps: f64,
    right_response_s: f64,
    p: &RssParams,
) -> f64 {
    let approach_m = lateral_approach_m(left_toward_mps, left_response_s, p)
        + lateral_approach_m(right_toward_mps, right_response_s, p);
    p.lat_margin_m + approach_m.max(0.0)
}

/// The shielded car and one other as RSS sees them, in the shielded car's lane frame: s along
/// the lane, d across it (positive to the left).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairGeometry {
    /// The other's centre ahead of the shielded car's, along the lane (m; negative: behind).
    pub ds_m: f64,
    /// The other's centre to the left of the shielded car's, across the lane (m).
    pub dd_m: f64,
    /// Bumper-to-bumper gap (m): |ds| − the half lengths.
    pub lon_gap_m: f64,
    /// Side-to-side gap (m): |dd| − the half widths.
    pub lat_gap_m: f64,
    /// The shielded car's speed along the lane (m/s).
    pub my_lon_mps: f64,
    /// The other's speed along the lane (m/s).
    pub other_lon_mps: f64,
    /// The shielded car's speed across the lane, positive to the left (m/s).
    pub my_lat_mps: f64,
    /// The other's speed across the lane, positive to the left (m/s).
    pub other_lat_mps: f64,
}

/// Whether each of the two distances is safe, and the gaps they were held to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSafety {
    /// The longitudinal gap is at least the safe one.
    pub lon_safe: bool,
    /// The lateral gap is at least the safe one.
    pub lat_safe: bool,
    /// The safe longitudinal gap (m).
    pub safe_lon_gap_m: f64,
    /// The safe lateral gap (m).
    pub safe_lat_gap_m: f64,
}

impl PairSafety {
    /// RSS's dangerous situation: both distances unsafe.
    pub fn dangerous(&self) -> bool {
        !self.lon_safe && !self.lat_safe
    }
}

/// Judges the pair by Definitions 1 and 7: the rear car (by `ds_m`) is the one whose response
/// time enters the longitudinal distance; the lateral one takes each car's own.
pub fn judge(g: &PairGeometry, p: &RssParams) -> PairSafety {
    let other_ahead = g.ds_m >= 0.0;
    let safe_lon_gap_m = if other_ahead {
        safe_longitudinal_gap_m(g.my_lon_mps, g.other_lon_mps, p.response_time_s, p)
    } else {
        safe_longitudinal_gap_m(g.other_lon_mps, g.my_lon_mps, p.other_response_time_s, p)
    };
    let other_left = g.dd_m >= 0.0;
    // Each car's lateral speed toward the other.
    let (my_toward_mps, other_toward_mps) = if other_left {
        (g.my_lat_mps, -g.other_lat_mps)
    } else {
        (-g.my_lat_mps, g.other_lat_mps)
    };
    let safe_lat_gap_m = safe_lateral_gap_m(
        my_toward_mps,
        p.response_time_s,
        other_toward_mps,
        p.other_response_time_s,
        p,
    );
    PairSafety {
        lon_safe: g.lon_gap_m >= safe_lon_gap_m,
        lat_safe: g.lat_gap_m >= safe_lat_gap_m,
        safe_lon_gap_m,
        safe_lat_gap_m,
    }
}

/// Which proper responses a dangerous situation calls for (RSS Definition 10, same
/// direction): the longitudinal one if the longitudinal distance was safe just before the
/// blame time (the last instant the situation was not dangerous), the lateral one if the
/// lateral distance was.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Responses {
    /// The rear car brakes at least a_min,brake (the front car: at most a_max,brake).
    pub longitudinal: bool,
    /// Each car brakes its lateral speed toward the other to zero, then moves no closer.
    pub lateral: bool,
}

impl Responses {
    /// The responses for a situation that turned dangerous after `before` (the pair's safety
    /// at the last instant it was not dangerous); `None`: first seen already dangerous, when
    /// nothing is known of the blame time and both responses apply.
    pub fn at_blame_time(before: Option<&PairSafety>) -> Self {
        match before {
            Some(b) => Self {
                longitudinal: b.lon_safe,
                lateral: b.lat_safe,
            },
            None => Self {
                longitudinal: true,
                lateral: true,
            },
        }
    }

    /// Their name in events: `longitudinal`, `lateral` or `longitudinal+lateral`.
    pub fn name(&self) -> &'static str {
        match (self.longitudinal, self.lateral) {
            (true, true) => "longitudinal+lateral",
            (true, false) => "longitudinal",
            (false, true) => "lateral",
            (false, false) => "none",
        }
    }
}
