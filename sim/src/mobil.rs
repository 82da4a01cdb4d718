//! MOBIL lane changes for the IDM drivers (Kesting, Treiber & Helbing, "General Lane-Changing
//! Model MOBIL for Car-Following Models", Transportation Research Record 1999, 86–94, 2007).
//!
//! A driver c considers moving to a neighbouring lane. The change affects three drivers: c
//! itself, its old follower o (who gets c's old leader in front) and its new follower n in the
//! target lane (who gets c in front). With ã the IDM accelerations after the change and a those
//! before:
//!
//! ```text
//! safety:     ã_n ≥ −b_safe
//! incentive:  ã_c − a_c + p · [(ã_n − a_n) + (ã_o − a_o)] + a_bias > Δa_th
//! ```
//!
//! p is the politeness, Δa_th the switching threshold, b_safe the deceleration a change may
//! impose on the new follower at most, and a_bias a bias toward leaving a lane that ends (0 for
//! any other change). A lane's end is a standing obstacle of zero length at the end of its
//! centreline: it is the driver's leader in that lane until MOBIL finds a gap (the "virtual
//! standing vehicle" of the paper's mandatory changes). A driver without a follower leaves no one
//! to disadvantage: that term is 0, and a change without a new follower is safe.
//!
//! Pure functions, positions as arc lengths s along the lanes' common direction: the world
//! projects the drivers into the lanes' frames.

use serde::{Deserialize, Serialize};

use mergesim_types::bounds::{self, Bound};

use crate::error::SimError;
use crate::idm::{IdmParams, Leader, idm_acceleration};

/// MOBIL parameters (`[sim.mobil]`). Defaults: Kesting, Treiber & Helbing (2007) for the
/// politeness, threshold and safe deceleration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MobilParams {
    /// Politeness factor p: the weight of the two followers' gains and losses.
    pub politeness: f64,
    /// Switching threshold Δa_th (m/s²): the least advantage worth a change.
    pub threshold_mps2: f64,
    /// Safe deceleration b_safe (m/s², positive): the most a change may make the new follower
    /// brake.
    pub safe_decel_mps2: f64,
    /// Bias a_bias toward leaving a lane that ends (m/s²), added to the incentive of such a
    /// change only.
    pub ending_lane_bias_mps2: f64,
    /// Least time between two changes of one driver (s): a change is not reconsidered while
    /// the car is still crossing over.
    pub min_time_between_changes_s: f64,
    /// Clearance (m) the car keeps from either bound of a lane that narrows to its end: the
    /// standing obstacle stands where the car would no longer fit with it.
    pub end_clearance_m: f64,
}

impl Default for MobilParams {
    fn default() -> Self {
        Self {
            politeness: 0.2,
            threshold_mps2: 0.1,
            safe_decel_mps2: 4.0,
            // Kesting et al.'s keep-right bias a_bias = 0.3 m/s², here toward the lane that
            // continues.
            ending_lane_bias_mps2: 0.3,
            // The longest lane change the tracker drives, 4.20 s (bmw_320i at 30 m/s), rounded
            // up to 0.5 s (docs/parameters.md; `tests/mobil_criteria.rs`).
            min_time_between_changes_s: 4.5,
            // The largest excursion of a car's corners from their place on the centreline while
            // keeping a lane, 0.524 m (vw_vanagon at 30 m/s on the 300 m curve), plus the
            // contact tolerance, rounded up to 0.05 m (docs/parameters.md;
            // `tests/mobil_criteria.rs`).
            end_clearance_m: 0.55,
        }
    }
}

/// Allowed ranges of the MOBIL parameters (README "Limits").
pub const MOBIL_BOUNDS: &[Bound] = &[
    Bound::closed("politeness", 0.0, 10.0, ""),
    Bound::closed("threshold_mps2", 0.0, 10.0, "m/s²"),
    Bound::above("safe_decel_mps2", 0.0, 30.0, "m/s²"),
    Bound::closed("ending_lane_bias_mps2", 0.0, 10.0, "m/s²"),
    Bound::closed("min_time_between_changes_s", 0.0, 60.0, "s"),
    Bound::closed("end_clearance_m", 0.0, 5.0, "m"),
];

impl MobilParams {
    /// Whether every field has its default value.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field against [`MOBIL_BOUNDS`]; the error names it (`mobil.<field>`).
    pub fn validate(&self) -> Result<(), SimError> {
        bounds::check_all(
            "mobil",
            MOBIL_BOUNDS,
            &[
                ("politeness", self.politeness),
                ("threshold_mps2", self.threshold_mps2),
                ("safe_decel_mps2", self.safe_decel_mps2),
                ("ending_lane_bias_mps2", self.ending_lane_bias_mps2),
                (
                    "min_time_between_changes_s",
                    self.min_time_between_changes_s,
                ),
                ("end_clearance_m", self.end_clearance_m),
            ],
        )?;
        Ok(())
    }
}

/// A driver as MOBIL sees it: arc length of its centre, speed, desired speed and body length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneDriver {
    /// Arc length of the centre along the lanes' direction (m).
    pub s_m: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
    /// Desired speed v₀ (m/s).
    pub desired_speed_mps: f64,
    /// Body length (m); 0 for a lane's end.
    pub length_m: f64,
}

impl LaneDriver {
    /// A lane's end at arc length `s_m`: a standing obstacle of zero length.
    pub fn lane_end(s_m: f64) -> Self {
        Self {
            s_m,
            speed_mps: 0.0,
            desired_speed_mps: 0.0,
            length_m: 0.0,
        }
    }
}

/// The drivers around a considered change: the changer's leader and follower in its own lane
/// now (the leader may be the lane's end), and in the target lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbourhood {
    /// The driver considering the change (c).
    pub me: LaneDriver,
    /// Its leader now, in its own lane (or that lane's end).
    pub leader_now: Option<LaneDriver>,
    /// Its follower now, in its own lane (o).
    pub follower_now: Option<LaneDriver>,
    /// Who would lead it in the target lane (or that lane's end).
    pub leader_after: Option<LaneDriver>,
    /// Who would follow it in the target lane (n).
    pub follower_after: Option<LaneDriver>,
    /// True if the change leaves a lane that ends (a_bias applies).
    pub leaving_ending_lane: bool,
}

/// The accelerations (m/s²) of the three drivers a change affects, before and after it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChangeAccelerations {
    /// a_c, ã_c.
    pub me: (f64, f64),
    /// a_o, ã_o of the old follower, if there is one.
    pub old_follower: Option<(f64, f64)>,
    /// a_n, ã_n of the new follower, if there is one.
    pub new_follower: Option<(f64, f64)>,
}

/// MOBIL's verdict on one considered change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    /// The incentive's left side, bias included (m/s²).
    pub incentive_mps2: f64,
    /// Whether the safety criterion holds.
    pub safe: bool,
    /// Whether to change: safe and incentive above the threshold.
    pub change: bool,
}

/// The IDM acceleration of `follower` behind `leader` (or on a free road), with the IDM's
/// bumper-to-bumper gap.
fn accel_behind(idm: &IdmParams, follower: &LaneDriver, leader: Option<&LaneDriver>) -> f64 {
    let leader = leader.map(|l| Leader {
        index: 0,
        gap_m: l.s_m - follower.s_m - 0.5 * (l.length_m + follower.length_m),
        speed_mps: l.speed_mps,
    });
    idm_acceleration(
        idm,
        follower.speed_mps,
        follower.desired_speed_mps,
        leader.as_ref(),
    )
}

/// The accelerations before and after the change described by `n` (module doc).
pub fn change_accelerations(idm: &IdmParams, n: &Neighbourhood) -> ChangeAccelerations {
    let me_now = accel_behind(idm, &n.me, n.leader_now.as_ref());
    let me_after = accel_behind(idm, &n.me, n.leader_after.as_ref());
    let old_follower = n.follower_now.map(|o| {
        (
            accel_behind(idm, &o, Some(&n.me)),
            accel_behind(idm, &o, n.leader_now.as_ref()),
        )
    });
    let new_follower = n.follower_after.map(|f| {
        (
            accel_behind(idm, &f, n.leader_after.as_ref()),
            accel_behind(idm, &f, Some(&n.me)),
        )
    });
    ChangeAccelerations {
        me: (me_now, me_after),
        old_follower,
        new_follower,
    }
}

/// MOBIL's safety and incentive criteria on the accelerations `a` (module doc).
pub fn verdict(
    params: &MobilParams,
    a: &ChangeAccelerations,
    leaving_ending_lane: bool,
) -> Verdict {
    let gain = |pair: Option<(f64, f64)>| pair.map_or(0.0, |(now, after)| after - now);
    let bias = if leaving_ending_lane {
        params.ending_lane_bias_mps2
    } else {
        0.0
    };
    let incentive_mps2 = (a.me.1 - a.me.0)
        + params.politeness * (gain(a.new_follower) + gain(a.old_follower))
        + bias;
    let safe = a
        .new_follower
        .is_none_or(|(_, after)| after >= -params.safe_decel_mps2);
    Verdict {
        incentive_mps2,
        safe,
        change: safe && incentive_mps2 > params.threshold_mps2,
    }
}

/// Whether the driver of `n` changes lanes, and why: [`change_accelerations`] then
/// [`verdict`].
pub fn decide(idm: &IdmParams, params: &MobilParams, n: &Neighbourhood) -> Verdict {
    verdict(params, &change_accelerations(idm, n), n.leaving_ending_lane)
}

#[cfg(test)]
mod tests;
