//! Routing on hand-made lane graphs.

use super::*;
use mergesim_types::lanes::{LaneRoadSpec, LaneSpec, LaneTolerances};

/// Lanes 1 → 3 (right carriageway, 100 m each) and 2 → 4 beside them on the left (lane 2 is
/// lane 1's left neighbour, lane 4 lane 3's); lane 5 is a lone lane far away.
fn grid() -> LaneRoad {
    let lane = |id, y: f64, x0: f64| LaneSpec::new(LaneId(id), vec![[x0, y], [x0 + 100.0, y]], 3.5);
    let mut l1 = lane(1, 0.0, 0.0);
    let mut l2 = lane(2, 3.5, 0.0);
    let mut l3 = lane(3, 0.0, 100.0);
    let mut l4 = lane(4, 3.5, 100.0);
    let l5 = lane(5, 50.0, 0.0);
    l1.left = Some(LaneId(2));
    l2.right = Some(LaneId(1));
    l3.left = Some(LaneId(4));
    l4.right = Some(LaneId(3));
    l1.successors = vec![LaneId(3)];
    l3.predecessors = vec![LaneId(1)];
    l2.successors = vec![LaneId(4)];
    l4.predecessors = vec![LaneId(2)];
    LaneRoad::new(&LaneRoadSpec {
        lanes: vec![l1, l2, l3, l4, l5],
        tolerances: LaneTolerances::default(),
    })
    .unwrap()
}

#[test]
fn a_route_across_a_lane_change() {
    let road = grid();
    let route = shortest_route(&road, LaneId(1), &[LaneId(4)]).unwrap();
    // Two lanes entered either way (1 → 2 → 4 or 1 → 3 → 4), 200 m each: the tie goes to the
    // lane with the smaller id popped first.
    assert_eq!(route.len(), 3);
    assert_eq!(route.first(), Some(&LaneId(1)));
    assert_eq!(route.last(), Some(&LaneId(4)));
    for pair in route.windows(2) {
        assert!(next_lanes(&road, pair[0]).contains(&pair[1]));
    }
    // Straight on: no lane change.
    assert_eq!(
        shortest_route(&road, LaneId(1), &[LaneId(3)]).unwrap(),
        vec![LaneId(1), LaneId(3)]
    );
    // Already there.
    assert_eq!(
        shortest_route(&road, LaneId(3), &[LaneId(3)]).unwrap(),
        vec![LaneId(3)]
    );
}

#[test]
fn an_unreachable_goal_has_no_route() {
    let road = grid();
    assert_eq!(shortest_route(&road, LaneId(1), &[LaneId(5)]), None);
    // No going back against the driving direction.
    assert_eq!(shortest_route(&road, LaneId(3), &[LaneId(1)]), None);
    assert_eq!(shortest_route(&road, LaneId(1), &[]), None);
}

#[test]
fn lanes_touching_a_region() {
    let road = grid();
    let near = |p: [f64; 2]| (p[0] - 150.0).hypot(p[1] - 3.5) <= 1.0;
    assert_eq!(lanes_touching(&road, near), vec![LaneId(4)]);
}
