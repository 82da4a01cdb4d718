//! Recorded traffic in the safety checks (`crate::world` spawns it from
//! `SimConfig::recorded_traffic`).
//!
//! Recorded vehicles carry the ids from [`SafetyMonitor::set_recorded_from`] on. Pairs of a
//! simulated and a recorded vehicle are checked like any pair (collision, gap, TTC, TET, the
//! same parry queries). Pairs of two recorded vehicles are *not* checked: how close the
//! recorded drivers came to each other is the recording's business, not the planners', and a
//! recording's boxes often touch (measurement noise, rectangles larger than the cars). Nor are
//! recorded vehicles checked against the road edges.
//!
//! # Who hit whom
//! A collision of a simulated vehicle with a recorded one is *caused by the replay*
//! ([`CollisionEvent::caused_by_replay`]) when the recorded vehicle is the rear one at the
//! first checked instant of contact: the simulated vehicle's box centre lies ahead of the
//! recorded one's along the recorded heading, within ±45° of it (its offset along the heading
//! is positive and larger than its offset across). A recording never reacts, so a recorded car
//! running into a simulated one from behind is not the planner's doing; these collisions are
//! counted apart ([`SafetySummary::collisions_caused_by_replay`]). Every other collision with
//! a recorded vehicle (the simulated one hitting it from behind, from the side, cutting in
//! so close that the recorded car's front touches its side behind its centre) counts as the
//! simulated vehicle's own.

use mergesim_types::VehicleId;

use super::{BodyState, PairSafety, SafetyMonitor};

impl SafetyMonitor {
    /// Vehicles with an id ≥ `first_recorded_id` are recorded traffic (module doc).
    pub fn set_recorded_from(&mut self, first_recorded_id: VehicleId) {
        self.recorded_from = Some(first_recorded_id);
    }

    /// Whether `id` is a recorded vehicle.
    pub fn is_recorded(&self, id: VehicleId) -> bool {
        self.recorded_from.is_some_and(|first| id >= first)
    }

    /// Whether the pair is one the monitor leaves out: two recorded vehicles.
    pub(super) fn skips_pair(&self, a: VehicleId, b: VehicleId) -> bool {
        self.is_recorded(a) && self.is_recorded(b)
    }

    /// Whether a collision starting now between `a` and `b` is caused by the replay (module
    /// doc).
    pub(super) fn caused_by_replay(&self, a: &BodyState, b: &BodyState) -> bool {
        let (recorded, simulated) = match (self.is_recorded(a.id), self.is_recorded(b.id)) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            _ => return false,
        };
        recorded_is_behind(recorded, simulated)
    }

    /// Minimum gap (m) and minimum TTC (s) over the pairs of a simulated and a recorded vehicle.
    pub(super) fn recorded_figures(&self, pairs: &[PairSafety]) -> (Option<f64>, Option<f64>) {
        let mut gap: Option<f64> = None;
        let mut ttc: Option<f64> = None;
        for p in pairs
            .iter()
            .filter(|p| self.is_recorded(p.id_a) != self.is_recorded(p.id_b))
        {
            gap = Some(gap.map_or(p.min_gap_m, |g| g.min(p.min_gap_m)));
            if let Some(t) = p.min_ttc_s {
                ttc = Some(ttc.map_or(t, |m: f64| m.min(t)));
            }
        }
        (gap, ttc)
    }
}

/// Whether `simulated`'s centre lies within ±45° ahead of `recorded` along its heading.
pub fn recorded_is_behind(recorded: &BodyState, simulated: &BodyState) -> bool {
    let (s, c) = recorded.yaw_rad.sin_cos();
    let dx = simulated.x_m - recorded.x_m;
    let dy = simulated.y_m - recorded.y_m;
    let along_m = dx * c + dy * s;
    let across_m = -dx * s + dy * c;
    along_m > 0.0 && across_m.abs() < along_m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(id: VehicleId, x_m: f64, y_m: f64, yaw_rad: f64) -> BodyState {
        BodyState::standing(id, [x_m, y_m, yaw_rad], [4.5, 1.8, 1.3])
    }

    #[test]
    fn behind_means_within_45_degrees_ahead_of_the_recorded_heading() {
        let rec = body(5, 0.0, 0.0, 0.0);
        assert!(recorded_is_behind(&rec, &body(0, 4.4, 0.3, 0.0)));
        assert!(!recorded_is_behind(&rec, &body(0, -4.4, 0.3, 0.0)));
        // Beside it (a cut-in touching its front corner from the side).
        assert!(!recorded_is_behind(&rec, &body(0, 1.0, 1.8, 0.0)));
        // The recorded car heading +y: ahead is +y.
        let up = body(5, 0.0, 0.0, std::f64::consts::FRAC_PI_2);
        assert!(recorded_is_behind(&up, &body(0, 0.2, 4.4, 0.0)));
        assert!(!recorded_is_behind(&up, &body(0, 4.4, 0.2, 0.0)));
    }
}
