//! Eq. 1's target lane on a route (`LaneRoadGeometry::route_target_lane`).

use mergesim_types::lanes::{LaneId, LaneRoad, LaneRoadSpec, LaneSpec, LaneTolerances};
use planner::lane_road_field::LaneRoadGeometry;

/// Lane 1 (y = 0, x 0–100) with its left neighbour 2 (y = 3.5, x 0–200) and its successor 3
/// (y = 0, x 100–200), lane 3's left neighbour being 2 as well.
fn road() -> LaneRoadGeometry {
    let mut l1 = LaneSpec::new(LaneId(1), vec![[0.0, 0.0], [100.0, 0.0]], 3.5);
    let mut l2 = LaneSpec::new(LaneId(2), vec![[0.0, 3.5], [200.0, 3.5]], 3.5);
    let mut l3 = LaneSpec::new(LaneId(3), vec![[100.0, 0.0], [200.0, 0.0]], 3.5);
    l1.left = Some(LaneId(2));
    l1.successors = vec![LaneId(3)];
    l3.predecessors = vec![LaneId(1)];
    l3.left = Some(LaneId(2));
    l2.right = Some(LaneId(1));
    let road = LaneRoad::new(&LaneRoadSpec {
        lanes: vec![l1, l2, l3],
        tolerances: LaneTolerances::default(),
    })
    .unwrap();
    LaneRoadGeometry::new(&road)
}

#[test]
fn the_route_sets_the_target_lane() {
    let g = road();
    let idx = |ids: &[u32]| g.route_indices(&ids.iter().map(|&i| LaneId(i)).collect::<Vec<_>>());
    let on_1 = [20.0, 0.0];
    let i = |id: u32| idx(&[id])[0];
    // Without a route: the lane-end rule (lane 1 goes on: its own lane).
    assert_eq!(g.route_target_lane(on_1, &[], 10.0), i(1));
    assert_eq!(g.target_lane(i(1)), i(1));
    // A lane change on the route: its next lane, the neighbour.
    assert_eq!(g.route_target_lane(on_1, &idx(&[1, 2]), 10.0), i(2));
    // Off the route: a neighbour on it.
    assert_eq!(g.route_target_lane(on_1, &idx(&[2]), 10.0), i(2));
    // A successor on the route: targeted only within the look-ahead of the lane's end.
    assert_eq!(g.route_target_lane(on_1, &idx(&[1, 3]), 10.0), i(1));
    assert_eq!(g.route_target_lane([95.0, 0.0], &idx(&[1, 3]), 10.0), i(3));
    // Ids the road does not have are dropped.
    assert_eq!(idx(&[1, 99, 3]), idx(&[1, 3]));
}
