//! Which lane a vehicle is in, its lane changes, and the merge zone, read off the road of lanes
//! (the metrics, the events and the road end all use these, so they agree on every road).
//!
//! - **Lane membership** (with hysteresis): a vehicle stays in its lane as long as its centre
//!   of gravity lies in it (bounds included); once it leaves it, it is in the first lane (in the
//!   road's description order) that holds the point, or, off every lane, the nearest lane
//!   ([`LaneRoad::nearest_lane`]). On the straight merge road this is "above the divider
//!   Y_lane: the through lane; below it, before the merge end: the ending lane".
//! - **Lane change**: the lane changes to one that is neither a successor nor a predecessor of
//!   the previous one (following a lane into its successor is no change). Its direction is
//!   `left` / `right` for a same-direction neighbour.
//! - **Merge zone**: the stretch where a lane that ends closed beside a neighbour narrows, from
//!   the start of its taper (the last centreline vertex from which its width only decreases to
//!   the end; the end itself for a lane that ends square) to [`MERGE_ZONE_TAIL_M`] past its end,
//!   measured along the neighbour it merges into (its left neighbour, else its right one). On the
//!   straight merge road: x from `merge_start_x_m` to `merge_end_x_m` + 20 m.

use mergesim_types::lanes::{LaneHit, LaneId, LaneRoad};

/// Length of road after the end of the ending lane that still counts as the merge zone (m).
pub const MERGE_ZONE_TAIL_M: f64 = 20.0;

/// The lane holding `p_m`, keeping `previous` while the point is still in it (module doc).
pub(crate) fn lane_of(lanes: &LaneRoad, previous: Option<LaneId>, p_m: [f64; 2]) -> LaneHit {
    if let Some(lane) = previous.and_then(|id| lanes.lane(id)) {
        let frame = lane.project(p_m);
        if lane.contains_frame(frame) {
            return LaneHit {
                lane: lane.id(),
                frame,
                excess_m: 0.0,
            };
        }
    }
    lanes
        .lanes_at(p_m)
        .into_iter()
        .next()
        .unwrap_or_else(|| lanes.nearest_lane(p_m))
}

/// A change from lane `from` to lane `to`, as an event's words: `None` if it is none (same lane,
/// or following a lane into its successor), else `Some("left")`, `Some("right")` or
/// `Some("across")` (a lane that is not a same-direction neighbour).
pub(crate) fn lane_change(lanes: &LaneRoad, from: LaneId, to: LaneId) -> Option<&'static str> {
    if from == to {
        return None;
    }
    let lane = lanes.lane(from)?;
    if lane.successors().contains(&to) || lane.predecessors().contains(&to) {
        return None;
    }
    Some(if lane.left_neighbour() == Some(to) {
        "left"
    } else if lane.right_neighbour() == Some(to) {
        "right"
    } else {
        "across"
    })
}

/// Signed distance of `p_m` to the bound of lane `from` facing lane `to` (m, in `from`'s frame;
/// negative inside `from`): 0 on the divider crossed by a change `from` → `to`.
pub(crate) fn beyond_divider_m(
    lanes: &LaneRoad,
    from: LaneId,
    to: LaneId,
    p_m: [f64; 2],
) -> Option<f64> {
    let lane = lanes.lane(from)?;
    let fp = lane.project(p_m);
    if lane.left_neighbour() == Some(to) {
        Some(fp.d_m - lane.left_d_m(fp.s_m))
    } else if lane.right_neighbour() == Some(to) {
        Some(lane.right_d_m(fp.s_m) - fp.d_m)
    } else {
        None
    }
}

/// The merge zone of a road (module doc).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MergeZone {
    /// The lane positions are measured along (the one the ending lane merges into).
    pub along: LaneId,
    /// The zone as arc lengths along `along` (m).
    pub s_m: [f64; 2],
    /// The world x of the zone's two ends (m): the taper's start, and the point
    /// [`MERGE_ZONE_TAIL_M`] past the lane's end straight on along its end direction (on the
    /// straight merge road, the merge section's start and its end + 20 m; on a curve the zone
    /// itself is `s_m`).
    pub x_m: [f64; 2],
}

impl MergeZone {
    /// The merge zone of the first lane (in description order) that ends closed beside a
    /// neighbour; `None` if the road has no such lane.
    pub(crate) fn of(lanes: &LaneRoad) -> Option<Self> {
        let end = lanes.lane_ends().iter().find(|e| {
            e.closed
                && lanes
                    .lane(e.lane)
                    .is_some_and(|l| l.left_neighbour().or(l.right_neighbour()).is_some())
        })?;
        let ending = lanes.lane(end.lane)?;
        let along = lanes.lane(ending.left_neighbour().or(ending.right_neighbour())?)?;
        let vertices = ending.centreline().vertices_m();
        let vs = ending.centreline().vertex_s_m();
        let widths: Vec<f64> = vs.iter().map(|&s| ending.width_m(s)).collect();
        let mut first = widths.len() - 1;
        while first > 0 && widths[first - 1] > widths[first] {
            first -= 1;
        }
        let start_m = vertices[first];
        let end_m = vertices[vertices.len() - 1];
        let t = ending.centreline().tangent(ending.length_m());
        let tail_m = [
            end_m[0] + MERGE_ZONE_TAIL_M * t[0],
            end_m[1] + MERGE_ZONE_TAIL_M * t[1],
        ];
        Some(Self {
            along: along.id(),
            s_m: [
                along.project(start_m).s_m,
                along.project(end_m).s_m + MERGE_ZONE_TAIL_M,
            ],
            x_m: [start_m[0], tail_m[0]],
        })
    }

    /// True if the point lies in the zone (its arc length along [`Self::along`] does).
    pub(crate) fn contains(&self, lanes: &LaneRoad, p_m: [f64; 2]) -> bool {
        lanes.lane(self.along).is_some_and(|l| {
            let s = l.project(p_m).s_m;
            s >= self.s_m[0] && s <= self.s_m[1]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::MergeRoad;
    use mergesim_types::lanes::{ENDING_LANE_ID, THROUGH_LANE_ID};

    #[test]
    fn straight_merge_road_zone_and_membership() {
        let road = MergeRoad::default();
        let lanes = road.lane_road().unwrap();
        let zone = MergeZone::of(&lanes).unwrap();
        assert_eq!(zone.along, THROUGH_LANE_ID);
        assert_eq!(zone.x_m, [160.0, 280.0]);
        assert!((zone.s_m[0] - 210.0).abs() < 1e-9 && (zone.s_m[1] - 330.0).abs() < 1e-9);
        assert!(zone.contains(&lanes, [200.0, 1.0]));
        assert!(!zone.contains(&lanes, [150.0, 5.0]));
        // Above the divider: the through lane; below it: the ending lane; on it, the lane the
        // vehicle was in.
        assert_eq!(lane_of(&lanes, None, [100.0, 4.0]).lane, THROUGH_LANE_ID);
        assert_eq!(lane_of(&lanes, None, [100.0, 3.0]).lane, ENDING_LANE_ID);
        assert_eq!(
            lane_of(&lanes, Some(ENDING_LANE_ID), [100.0, 3.5]).lane,
            ENDING_LANE_ID
        );
        assert_eq!(
            lane_of(&lanes, Some(THROUGH_LANE_ID), [100.0, 3.5]).lane,
            THROUGH_LANE_ID
        );
        assert_eq!(
            lane_change(&lanes, ENDING_LANE_ID, THROUGH_LANE_ID),
            Some("left")
        );
        assert_eq!(
            lane_change(&lanes, THROUGH_LANE_ID, ENDING_LANE_ID),
            Some("right")
        );
        let g = beyond_divider_m(&lanes, ENDING_LANE_ID, THROUGH_LANE_ID, [100.0, 3.2]).unwrap();
        assert!((g + 0.3).abs() < 1e-12, "{g}");
    }

    #[test]
    fn the_merge_zone_bends_with_the_road() {
        // The merge road bent on a 300 m arc: the through lane's radius is 298.25 m, so the
        // taper (x from 160 to 260 m on the divider, s from 210 to 310 m along the straight
        // through lane) lies at s × 298.25/300 along it, and the zone ends 20 m further on.
        let road = MergeRoad::default();
        let spec = mergesim_types::lanes::curved_merge_spec(&road, 300.0).unwrap();
        let lanes = LaneRoad::new(&spec).unwrap();
        let zone = MergeZone::of(&lanes).unwrap();
        let k = 298.25 / 300.0;
        assert!((zone.s_m[0] - 210.0 * k).abs() < 0.01, "{zone:?}");
        assert!((zone.s_m[1] - (310.0 * k + 20.0)).abs() < 0.01, "{zone:?}");
        // 1 m left of the divider (x = 100 m on it): the through lane; 1 m right: the ending
        // lane. On the divider at x = 250 m: in the zone; at x = 100 m: not.
        let through = lanes.lane(THROUGH_LANE_ID).unwrap();
        let at = |x_m: f64, d_m: f64| through.point((x_m + 50.0) * k, d_m);
        assert_eq!(
            lane_of(&lanes, None, at(100.0, -0.75)).lane,
            THROUGH_LANE_ID
        );
        assert_eq!(lane_of(&lanes, None, at(100.0, -2.75)).lane, ENDING_LANE_ID);
        assert!(zone.contains(&lanes, at(250.0, -1.75)));
        assert!(!zone.contains(&lanes, at(100.0, -1.75)));
    }
}
