//! Where the merge is, read from the road's lanes (`Observation::lanes`): the first lane that
//! ends closed beside a neighbour (the built-in road's lower lane, the on-ramp's acceleration
//! lane) is the *ending lane*, that neighbour the *through lane*. Positions are arc lengths s
//! along the through lane (a point's projection on its centreline).
//!
//! The merging zone runs from where the ending lane starts to narrow (its taper: the last
//! place, going back from its end, where its width is still its width at its start, to within
//! 1 cm) to its closed end. On the built-in road that is the merge section
//! (`merge_start_x_m`–`merge_end_x_m`); on the on-ramp road, the taper after the acceleration
//! lane. A road without a closed lane end has no merge: the planner is PF-ISO there.

use mergesim_types::lanes::{LaneId, LaneRoad};

/// Step of the search for the taper's start (m).
const TAPER_SEARCH_STEP_M: f64 = 1.0;
/// Width difference below which the ending lane counts as still full (m).
const FULL_WIDTH_TOLERANCE_M: f64 = 0.01;

/// The merge of a road (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct MergeGeometry {
    /// The lane that ends.
    pub ending_lane: LaneId,
    /// The lanes feeding the ending lane (e.g. the on-ramp's ramp): their cars come from the
    /// ending side too.
    pub feeding_lanes: Vec<LaneId>,
    /// The lane it merges into.
    pub through_lane: LaneId,
    /// s of the merging zone's entry on the through lane (m).
    pub merge_start_m: f64,
    /// s of the ending lane's end on the through lane (m).
    pub merge_end_m: f64,
}

/// Which side of the merge a car drives on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MergeSide {
    /// The ending lane or a lane feeding it.
    Ending,
    /// The through lane.
    Through,
}

impl MergeGeometry {
    /// The merge of `road`, if it has a closed lane end beside a neighbour.
    pub fn of(road: &LaneRoad) -> Option<Self> {
        let end = road.lane_ends().iter().find(|e| e.closed)?;
        let ending = road.lane(end.lane)?;
        let through_id = ending.left_neighbour().or(ending.right_neighbour())?;
        let through = road.lane(through_id)?;
        let full_m = ending.width_m(0.0);
        let mut taper_s = ending.length_m();
        while taper_s > 0.0 && ending.width_m(taper_s) < full_m - FULL_WIDTH_TOLERANCE_M {
            taper_s -= TAPER_SEARCH_STEP_M;
        }
        let taper_s = taper_s.max(0.0);
        let mid = [
            0.5 * (end.edge_m[0][0] + end.edge_m[1][0]),
            0.5 * (end.edge_m[0][1] + end.edge_m[1][1]),
        ];
        let merge_end_m = through.project(mid).s_m;
        let merge_start_m = through
            .project(ending.point(taper_s, 0.0))
            .s_m
            .min(merge_end_m);
        Some(Self {
            ending_lane: end.lane,
            feeding_lanes: ending.predecessors().to_vec(),
            through_lane: through_id,
            merge_start_m,
            merge_end_m,
        })
    }

    /// s and d of a point in the through lane's frame (m).
    pub fn frame(&self, road: &LaneRoad, p_m: [f64; 2]) -> Option<(f64, f64)> {
        road.lane(self.through_lane).map(|l| {
            let f = l.project(p_m);
            (f.s_m, f.d_m)
        })
    }

    /// The side of the merge a point is on (`None`: another lane).
    pub fn side(&self, road: &LaneRoad, p_m: [f64; 2]) -> Option<MergeSide> {
        let lane = road.nearest_lane(p_m).lane;
        if lane == self.through_lane {
            Some(MergeSide::Through)
        } else if lane == self.ending_lane || self.feeding_lanes.contains(&lane) {
            Some(MergeSide::Ending)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::MergeRoad;
    use mergesim_types::lanes::{ENDING_LANE_ID, THROUGH_LANE_ID};

    #[test]
    fn the_built_in_roads_merging_zone_is_its_merge_section() {
        let road = MergeRoad::default();
        let lanes = road.lane_road().unwrap();
        let g = MergeGeometry::of(&lanes).unwrap();
        assert_eq!(g.ending_lane, ENDING_LANE_ID);
        assert_eq!(g.through_lane, THROUGH_LANE_ID);
        // s is measured from the road's start.
        let start = road.merge_start_x_m - road.start_x_m;
        let end = road.merge_end_x_m - road.start_x_m;
        assert!(
            (g.merge_start_m - start).abs() <= TAPER_SEARCH_STEP_M,
            "{g:?}"
        );
        assert!((g.merge_end_m - end).abs() < 1e-6, "{g:?}");
        let y_low = road.lane_center_y_m(mergesim_types::Lane::Lower);
        assert_eq!(g.side(&lanes, [0.0, y_low]), Some(MergeSide::Ending));
    }
}
