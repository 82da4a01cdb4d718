//! Geometry of the merge road (paper Sec. III-A-2, the piecewise lower edge of Eq. 3).
//!
//! One description shared by the planner's road potential field and the simulator's road
//! collider, so the two can never disagree.
//!
//! Frame: X along the road (m), Y to the left (m), Z up. Two lanes of `lane_width_m` exist
//! until the merge section ends; the lower (right-hand) lane then ends:
//!
//! ```text
//!  y_upper ───────────────────────────────────────────────────────────  upper edge
//!           upper lane
//!  y_lane  - - - - - - - - - - - - - - - - - - ─────────────────────── divider / lower edge
//!           lower lane                      ／  (linear taper, Eq. 3: Y = k_sl·X + b)
//!  y_bottom ───────────────────────────────╱
//!          start_x        merge_start_x   merge_end_x                end_x
//! ```

use serde::{Deserialize, Serialize};

use crate::bounds::Bound;
use crate::error::InvalidParameter;
use crate::lanes::{
    ENDING_LANE_ID, LaneError, LaneId, LaneRoad, LaneRoadSpec, THROUGH_LANE_ID, merge_road_spec,
};

/// Which lane a vehicle starts in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lane {
    /// The lane that ends in the merge section (the paper's ego lane).
    Lower,
    /// The through lane (the paper's obstacle lane).
    Upper,
}

/// The merge road of the paper's scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MergeRoad {
    /// Width of one lane (m).
    pub lane_width_m: f64,
    /// Lateral position of the lower road edge before the merge section, Y_bottom (m).
    pub y_bottom_m: f64,
    /// Longitudinal start of the merge section, X_merge^start (m).
    pub merge_start_x_m: f64,
    /// Longitudinal end of the merge section, X_merge^end (m).
    pub merge_end_x_m: f64,
    /// Where the road begins (m).
    pub start_x_m: f64,
    /// Where the road ends (m).
    pub end_x_m: f64,
}

impl Default for MergeRoad {
    fn default() -> Self {
        Self {
            lane_width_m: 3.5,
            y_bottom_m: 0.0,
            merge_start_x_m: 160.0,
            merge_end_x_m: 260.0,
            start_x_m: -50.0,
            end_x_m: 700.0,
        }
    }
}

/// Allowed ranges of the road's fields (README "Limits"): lateral positions within ±1 km and
/// longitudinal ones within ±10 km of the origin, where Rapier's single precision still resolves
/// millimetres; a merge section of 10 m to 2 km.
pub const ROAD_BOUNDS: &[Bound] = &[
    Bound::closed("lane_width_m", 2.0, 6.0, "m"),
    Bound::closed("y_bottom_m", -1000.0, 1000.0, "m"),
    Bound::closed("merge_start_x_m", -10_000.0, 10_000.0, "m"),
    Bound::closed("merge_end_x_m", -10_000.0, 10_000.0, "m"),
    Bound::closed("start_x_m", -10_000.0, 10_000.0, "m"),
    Bound::closed("end_x_m", -10_000.0, 10_000.0, "m"),
];

/// Shortest and longest merge section (m).
pub const MERGE_SECTION_LENGTH_M: [f64; 2] = [10.0, 2000.0];

impl MergeRoad {
    /// Checks every field against [`ROAD_BOUNDS`] and the fields against each other; the error
    /// names the field and its value.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        crate::bounds::check_all(
            "road",
            ROAD_BOUNDS,
            &[
                ("lane_width_m", self.lane_width_m),
                ("y_bottom_m", self.y_bottom_m),
                ("merge_start_x_m", self.merge_start_x_m),
                ("merge_end_x_m", self.merge_end_x_m),
                ("start_x_m", self.start_x_m),
                ("end_x_m", self.end_x_m),
            ],
        )?;
        let merge_length_m = self.merge_end_x_m - self.merge_start_x_m;
        if merge_length_m > 0.0
            && !(MERGE_SECTION_LENGTH_M[0]..=MERGE_SECTION_LENGTH_M[1]).contains(&merge_length_m)
        {
            return Err(InvalidParameter::new(
                "road.merge_end_x_m",
                self.merge_end_x_m,
                format!(
                    "the merge section (road.merge_start_x_m = {} to here) must be {} to {} m long",
                    self.merge_start_x_m, MERGE_SECTION_LENGTH_M[0], MERGE_SECTION_LENGTH_M[1]
                ),
            ));
        }
        if self.start_x_m >= self.merge_start_x_m {
            return Err(InvalidParameter::new(
                "road.merge_start_x_m",
                self.merge_start_x_m,
                format!("must be greater than road.start_x_m = {}", self.start_x_m),
            ));
        }
        if self.merge_end_x_m <= self.merge_start_x_m {
            return Err(InvalidParameter::new(
                "road.merge_end_x_m",
                self.merge_end_x_m,
                format!(
                    "must be greater than road.merge_start_x_m = {}",
                    self.merge_start_x_m
                ),
            ));
        }
        if self.end_x_m <= self.merge_end_x_m {
            return Err(InvalidParameter::new(
                "road.end_x_m",
                self.end_x_m,
                format!(
                    "must be greater than road.merge_end_x_m = {}",
                    self.merge_end_x_m
                ),
            ));
        }
        Ok(())
    }

    /// Lateral position of the lane divider, Y_lane (m).
    pub fn y_lane_m(&self) -> f64 {
        self.y_bottom_m + self.lane_width_m
    }

    /// Lateral position of the upper road edge, Y_u (m).
    pub fn y_upper_m(&self) -> f64 {
        self.y_bottom_m + 2.0 * self.lane_width_m
    }

    /// Slope k_sl of the lower edge in the merge section (Eq. 3).
    pub fn taper_slope(&self) -> f64 {
        self.lane_width_m / (self.merge_end_x_m - self.merge_start_x_m)
    }

    /// Lateral position of the lower road edge Y_l(X), piecewise as in Eq. 3 (reading the
    /// paper's `k_sl·X_merge + b` as `k_sl·X + b`).
    pub fn lower_edge_y_m(&self, x_m: f64) -> f64 {
        if x_m < self.merge_start_x_m {
            self.y_bottom_m
        } else if x_m <= self.merge_end_x_m {
            self.y_bottom_m + self.taper_slope() * (x_m - self.merge_start_x_m)
        } else {
            self.y_lane_m()
        }
    }

    /// dY_l/dX of the lower edge (0 outside the merge section).
    pub fn lower_edge_slope(&self, x_m: f64) -> f64 {
        if x_m >= self.merge_start_x_m && x_m <= self.merge_end_x_m {
            self.taper_slope()
        } else {
            0.0
        }
    }

    /// True where the lane divider exists (two lanes side by side, before the merge ends).
    pub fn has_divider(&self, x_m: f64) -> bool {
        x_m < self.merge_end_x_m
    }

    /// Lateral centre of a lane where it exists at full width.
    pub fn lane_center_y_m(&self, lane: Lane) -> f64 {
        match lane {
            Lane::Lower => self.y_bottom_m + 0.5 * self.lane_width_m,
            Lane::Upper => self.y_bottom_m + 1.5 * self.lane_width_m,
        }
    }

    /// Vertices of the lower edge as a polyline from `start_x_m` to `end_x_m` (for colliders
    /// and drawing): the edge is exactly piecewise linear, so these four points describe it.
    pub fn lower_edge_polyline(&self) -> Vec<[f64; 2]> {
        vec![
            [self.start_x_m, self.y_bottom_m],
            [self.merge_start_x_m, self.y_bottom_m],
            [self.merge_end_x_m, self.y_lane_m()],
            [self.end_x_m, self.y_lane_m()],
        ]
    }

    /// The id of a lane in [`Self::lane_road`].
    pub fn lane_id(lane: Lane) -> LaneId {
        match lane {
            Lane::Upper => THROUGH_LANE_ID,
            Lane::Lower => ENDING_LANE_ID,
        }
    }

    /// This road as lanes (description): the through lane and the ending lane, whose right
    /// bound is the piecewise lower edge and which ends at `merge_end_x_m`.
    pub fn lane_road_spec(&self) -> LaneRoadSpec {
        merge_road_spec(self)
    }

    /// This road as a [`LaneRoad`]: the through lane, the ending lane with its (closed) end, the
    /// divider up to `merge_end_x_m`, the outer edges (upper edge; lower edge with the taper).
    /// Its queries give this road's figures (test `merge_road_as_lanes` in types/tests/lanes_road.rs).
    /// Fails only for a road that [`Self::validate`] refuses.
    pub fn lane_road(&self) -> Result<LaneRoad, LaneError> {
        LaneRoad::new(&self.lane_road_spec())
    }

    /// Vertices of the upper edge as a polyline.
    pub fn upper_edge_polyline(&self) -> Vec<[f64; 2]> {
        vec![
            [self.start_x_m, self.y_upper_m()],
            [self.end_x_m, self.y_upper_m()],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_edge_is_continuous_and_piecewise() {
        let road = MergeRoad::default();
        assert_eq!(road.lower_edge_y_m(0.0), road.y_bottom_m);
        assert!((road.lower_edge_y_m(road.merge_end_x_m) - road.y_lane_m()).abs() < 1e-12);
        assert_eq!(
            road.lower_edge_y_m(road.merge_end_x_m + 10.0),
            road.y_lane_m()
        );
        let mid = 0.5 * (road.merge_start_x_m + road.merge_end_x_m);
        assert!(
            (road.lower_edge_y_m(mid) - (road.y_bottom_m + 0.5 * road.lane_width_m)).abs() < 1e-12
        );
    }

    #[test]
    fn validate_names_the_bad_field() {
        let road = MergeRoad {
            merge_end_x_m: 100.0,
            ..MergeRoad::default()
        };
        let err = road.validate().unwrap_err().to_string();
        assert!(err.contains("merge_end_x_m"), "{err}");
    }
}
