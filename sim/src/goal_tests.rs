//! The goal semantics on hand-made cases.

use super::*;
use mergesim_types::lanes::{LaneRoadSpec, LaneSpec, LaneTolerances};

/// Two parallel straight lanes along +x, 100 m long, 3.5 m wide: lane 1 (y = 0) and lane 2
/// (y = 3.5, its left neighbour).
fn two_lanes() -> LaneRoad {
    let mut a = LaneSpec::new(LaneId(1), vec![[0.0, 0.0], [100.0, 0.0]], 3.5);
    a.left = Some(LaneId(2));
    let mut b = LaneSpec::new(LaneId(2), vec![[0.0, 3.5], [100.0, 3.5]], 3.5);
    b.right = Some(LaneId(1));
    LaneRoad::new(&LaneRoadSpec {
        lanes: vec![a, b],
        tolerances: LaneTolerances::default(),
    })
    .unwrap()
}

/// Whether `goal` is reached at `t_s` by a vehicle at `p` with heading `yaw_rad` and speed
/// `speed_mps`.
fn reached(
    goal: &Goal,
    t_s: f64,
    p: [f64; 2],
    yaw_rad: f64,
    speed_mps: f64,
    road: &LaneRoad,
) -> bool {
    let state = VehicleState {
        x_m: p[0],
        y_m: p[1],
        yaw_rad,
        speed_mps,
    };
    goal.is_reached(t_s, &state, road)
}

fn iv(start: f64, end: f64) -> Option<Interval> {
    Some(Interval { start, end })
}

#[test]
fn a_time_only_goal_is_reached_inside_its_interval_ends_included() {
    let road = two_lanes();
    let goal = Goal {
        states: vec![GoalState {
            time_s: iv(3.0, 4.0),
            ..GoalState::default()
        }],
    };
    let anywhere = |t| reached(&goal, t, [1e4, -1e4], 2.0, 99.0, &road);
    assert!(!anywhere(2.99));
    assert!(anywhere(3.0));
    assert!(anywhere(3.5));
    assert!(anywhere(4.0));
    assert!(!anywhere(4.01));
    assert_eq!(goal.time_end_s(), Some(4.0));
    assert!(!goal.has_position());
}

#[test]
fn every_condition_of_one_state_must_hold_at_the_same_instant() {
    let road = two_lanes();
    let goal = Goal {
        states: vec![GoalState {
            time_s: iv(0.0, 10.0),
            velocity_mps: iv(10.0, 12.0),
            position: Some(GoalPosition::Lanes(vec![LaneId(2)])),
            ..GoalState::default()
        }],
    };
    // All three hold.
    assert!(reached(&goal, 5.0, [50.0, 3.5], 0.0, 11.0, &road));
    // Each one missing in turn.
    assert!(!reached(&goal, 11.0, [50.0, 3.5], 0.0, 11.0, &road));
    assert!(!reached(&goal, 5.0, [50.0, 3.5], 0.0, 9.9, &road));
    assert!(!reached(&goal, 5.0, [50.0, 0.0], 0.0, 11.0, &road));
    assert_eq!(goal.velocity_midpoint_mps(), Some(11.0));
}

#[test]
fn any_one_goal_state_is_enough() {
    let road = two_lanes();
    let goal = Goal {
        states: vec![
            GoalState {
                position: Some(GoalPosition::Lanes(vec![LaneId(1)])),
                velocity_mps: iv(20.0, 30.0),
                ..GoalState::default()
            },
            GoalState {
                position: Some(GoalPosition::Lanes(vec![LaneId(2)])),
                ..GoalState::default()
            },
        ],
    };
    // In lane 1 too slow for the first state, but the second needs lane 2.
    assert!(!reached(&goal, 1.0, [50.0, 0.0], 0.0, 10.0, &road));
    assert!(reached(&goal, 1.0, [50.0, 0.0], 0.0, 25.0, &road));
    assert!(reached(&goal, 1.0, [50.0, 3.5], 0.0, 10.0, &road));
    // A time interval missing from one state: no time end for the goal.
    assert_eq!(goal.time_end_s(), None);
}

#[test]
fn shapes_rectangle_rotated_circle_and_polygon() {
    let rect = GoalShape::Rectangle {
        length_m: 10.0,
        width_m: 2.0,
        orientation_rad: std::f64::consts::FRAC_PI_2,
        center_m: [5.0, 5.0],
    };
    // Rotated a quarter turn: 10 m along y, 2 m along x.
    assert!(rect.contains([5.0, 9.9]));
    assert!(rect.contains([5.9, 5.0]));
    assert!(!rect.contains([9.0, 5.0]));
    assert!(!rect.contains([5.0, 10.1]));
    let circle = GoalShape::Circle {
        radius_m: 2.0,
        center_m: [0.0, 0.0],
    };
    assert!(circle.contains([2.0, 0.0]));
    assert!(!circle.contains([1.5, 1.5]));
    // An L-shaped polygon: its notch is outside.
    let poly = GoalShape::Polygon {
        vertices_m: vec![
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 1.0],
            [1.0, 1.0],
            [1.0, 4.0],
            [0.0, 4.0],
        ],
    };
    assert!(poly.contains([0.5, 3.0]));
    assert!(poly.contains([3.0, 0.5]));
    assert!(!poly.contains([3.0, 3.0]));
    assert!(poly.contains([4.0, 0.5]), "on an edge counts as inside");
    let road = two_lanes();
    let goal = Goal {
        states: vec![GoalState {
            position: Some(GoalPosition::Shapes(vec![circle, poly])),
            ..GoalState::default()
        }],
    };
    assert!(reached(&goal, 0.0, [0.5, 3.0], 0.0, 0.0, &road));
    assert!(!reached(&goal, 0.0, [3.0, 3.0], 0.0, 0.0, &road));
}

#[test]
fn orientation_is_compared_modulo_a_turn() {
    let across_pi = Interval {
        start: 3.0,
        end: 3.3,
    };
    // −3.1 rad is 3.183 rad one turn on.
    assert!(across_pi.contains_angle(-3.1));
    assert!(across_pi.contains_angle(3.1));
    assert!(!across_pi.contains_angle(2.9));
    assert!(!across_pi.contains_angle(-2.9));
    let around_zero = Interval {
        start: -0.2,
        end: 0.2,
    };
    assert!(around_zero.contains_angle(0.1 + std::f64::consts::TAU));
    assert!(!around_zero.contains_angle(0.3));
    let road = two_lanes();
    let goal = Goal {
        states: vec![GoalState {
            orientation_rad: Some(around_zero),
            position: Some(GoalPosition::Shapes(vec![GoalShape::Circle {
                radius_m: 5.0,
                center_m: [50.0, 0.0],
            }])),
            ..GoalState::default()
        }],
    };
    assert!(reached(&goal, 0.0, [50.0, 0.0], 0.1, 10.0, &road));
    assert!(!reached(&goal, 0.0, [50.0, 0.0], 0.5, 10.0, &road));
}
