//! Road potential field: lane divider (paper Eq. 2) and road edges (Eq. 3) on the straight
//! `MergeRoad`, in X and Y. The planners use the lane-frame field (`lane_road_field.rs`); this
//! one is the reference the tests and the `lane_road_field` bench compare it with, and
//! `edge_term` (e(g) and e'(g)) is shared by both.
//!
//! Readings of the paper (listed in `planner/README.md`):
//! - Eq. 3 writes ½ ξ (1/(Y − Y_{l,u} − l_w/2))² for both edges; we use the clearance
//!   g = d − l_w/2 between the vehicle's side and the edge, d the distance from the centre to
//!   the edge (Y − Y_l for the lower edge, Y_u − Y for the upper), so both edges are symmetric.
//! - The lower edge is piecewise (`MergeRoad::lower_edge_y_m`), with the taper Y = k_sl·X + b
//!   (the paper's `k_sl X_merge + b` is a typo for X).
//! - ½ ξ / g² is infinite at g = 0: below the clearance g_c it continues along its tangent, so
//!   the field is C¹, finite everywhere, and still pushes back on and beyond the edge.
//! - The divider (Eq. 2) exists while two lanes exist, `MergeRoad::has_divider`.

use mergesim_types::MergeRoad;

/// The numbers of the road terms, Eqs. 2–3, shared by [`RoadField`] and the planners'
/// `LaneRoadField`; built once from `PlannerParams` (`derived_params`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoadFieldParams {
    /// A_lane, height of the lane-divider ridge of Eq. 2 (`lane_amplitude`).
    pub lane_amplitude: f64,
    /// σ of the lane-divider Gaussian of Eq. 2 (m; `lane_sigma_m`).
    pub lane_sigma_m: f64,
    /// ξ, scale of the edge field ½ ξ / g² of Eq. 3 (m²; `edge_gain_m2`).
    pub edge_gain_m2: f64,
    /// Clearance g_c below which Eq. 3's edge field is linear (m; `edge_clamp_distance_m`).
    pub edge_clamp_distance_m: f64,
}

/// Road field of one vehicle (its half-width enters the edge clearance).
#[derive(Clone, Copy, Debug)]
pub struct RoadField<'a> {
    /// The road.
    pub road: &'a MergeRoad,
    /// A_lane.
    pub lane_amplitude: f64,
    /// σ of the divider (m).
    pub lane_sigma_m: f64,
    /// ξ (m²).
    pub edge_gain_m2: f64,
    /// Clearance g_c below which the edge field is linear (m).
    pub edge_clamp_distance_m: f64,
    /// l_w / 2 of the vehicle (m).
    pub half_width_m: f64,
}

/// Edge term e(g) = ½ ξ / g² for g ≥ g_c, its tangent line below, and de/dg.
pub(crate) fn edge_term(gain_m2: f64, clamp_m: f64, clearance_m: f64) -> (f64, f64) {
    if clearance_m >= clamp_m {
        let inv = 1.0 / clearance_m;
        (0.5 * gain_m2 * inv * inv, -gain_m2 * inv * inv * inv)
    } else {
        let inv = 1.0 / clamp_m;
        let value_c = 0.5 * gain_m2 * inv * inv;
        let slope_c = -gain_m2 * inv * inv * inv;
        (value_c + slope_c * (clearance_m - clamp_m), slope_c)
    }
}

impl RoadField<'_> {
    /// U_LD at (x, y), Eq. 2 (zero where the divider has ended).
    pub fn lane_value(&self, x_m: f64, y_m: f64) -> f64 {
        if !self.road.has_divider(x_m) {
            return 0.0;
        }
        let dy = y_m - self.road.y_lane_m();
        self.lane_amplitude * (-dy * dy / (2.0 * self.lane_sigma_m * self.lane_sigma_m)).exp()
    }

    /// ∇U_LD, Eq. 2.
    pub fn lane_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        if !self.road.has_divider(x_m) {
            return [0.0, 0.0];
        }
        let s2 = self.lane_sigma_m * self.lane_sigma_m;
        let dy = y_m - self.road.y_lane_m();
        let u = self.lane_amplitude * (-dy * dy / (2.0 * s2)).exp();
        [0.0, -u * dy / s2]
    }

    /// Clearances (upper, lower) of the vehicle's sides to the edges at (x, y) (m).
    fn clearances(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let upper = self.road.y_upper_m() - y_m - self.half_width_m;
        let lower = y_m - self.road.lower_edge_y_m(x_m) - self.half_width_m;
        (upper, lower)
    }

    /// U_RE at (x, y): both edges, Eq. 3.
    pub fn edge_value(&self, x_m: f64, y_m: f64) -> f64 {
        let (g_upper, g_lower) = self.clearances(x_m, y_m);
        let (e_upper, _) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g_upper);
        let (e_lower, _) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g_lower);
        e_upper + e_lower
    }

    /// ∇U_RE, Eq. 3 (the taper slope k_sl enters ∂/∂X inside the merge section).
    pub fn edge_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let (g_upper, g_lower) = self.clearances(x_m, y_m);
        let (_, de_upper) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g_upper);
        let (_, de_lower) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g_lower);
        // g_upper = Y_u − y − w/2; g_lower = y − Y_l(x) − w/2.
        [
            -de_lower * self.road.lower_edge_slope(x_m),
            -de_upper + de_lower,
        ]
    }

    /// U_LD + U_RE.
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.lane_value(x_m, y_m) + self.edge_value(x_m, y_m)
    }

    /// ∇(U_LD + U_RE).
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let lane = self.lane_gradient(x_m, y_m);
        let edge = self.edge_gradient(x_m, y_m);
        [lane[0] + edge[0], lane[1] + edge[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;

    fn field(road: &MergeRoad) -> RoadField<'_> {
        let p = PlannerParams::default();
        RoadField {
            road,
            lane_amplitude: p.lane_amplitude,
            lane_sigma_m: p.lane_sigma_m,
            edge_gain_m2: p.edge_gain_m2,
            edge_clamp_distance_m: p.edge_clamp_distance_m,
            half_width_m: 0.805,
        }
    }

    fn central_difference(f: impl Fn(f64, f64) -> f64, x: f64, y: f64) -> [f64; 2] {
        let h = 1e-6;
        [
            (f(x + h, y) - f(x - h, y)) / (2.0 * h),
            (f(x, y + h) - f(x, y - h)) / (2.0 * h),
        ]
    }

    #[test]
    fn gradients_match_central_differences() {
        let road = MergeRoad::default();
        let f = field(&road);
        // Points away from the kinks of the lower edge (x = 160, 260) and the clamp switch.
        let points = [
            (10.0, 1.75),
            (10.0, 3.1),
            (10.0, 5.25),
            (10.0, 6.0),
            (180.0, 2.2),
            (230.0, 3.9),
            (250.0, 4.6),
            (300.0, 5.0),
            (10.0, 0.85), // clearance 0.045 m: on the linear continuation
            (10.0, -1.0), // beyond the edge
        ];
        for (x, y) in points {
            let analytic = f.gradient(x, y);
            let numeric = central_difference(|x, y| f.value(x, y), x, y);
            for k in 0..2 {
                let scale = 1.0 + numeric[k].abs();
                assert!(
                    (analytic[k] - numeric[k]).abs() < 1e-6 * scale,
                    "({x}, {y}) component {k}: analytic {} numeric {}",
                    analytic[k],
                    numeric[k]
                );
            }
        }
    }

    #[test]
    fn edge_field_is_continuous_at_the_clamp_and_finite_beyond_the_edge() {
        let (gain, clamp) = (0.01, 0.1);
        let (below, _) = edge_term(gain, clamp, clamp - 1e-12);
        let (above, _) = edge_term(gain, clamp, clamp + 1e-12);
        assert!((below - above).abs() < 1e-6);
        let (far_beyond, slope) = edge_term(gain, clamp, -5.0);
        assert!(far_beyond.is_finite() && slope < 0.0);
    }

    #[test]
    fn divider_ridge_peaks_at_the_divider_and_vanishes_after_the_merge() {
        let road = MergeRoad::default();
        let f = field(&road);
        let y_lane = road.y_lane_m();
        assert!((f.lane_value(50.0, y_lane) - f.lane_amplitude).abs() < 1e-15);
        assert_eq!(f.lane_value(road.merge_end_x_m + 1.0, y_lane), 0.0);
    }
}
