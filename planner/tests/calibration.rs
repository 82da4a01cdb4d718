//! The criteria that fix the planner's parameters (`docs/parameters.md`), checked on the
//! defaults. None of them looks at how PF-CS, PF-SP and PF-ISO compare: they are properties
//! of one vehicle alone, of two side by side in their lanes, or of car following.
//!
//! `cargo run --release -p planner --example calibrate_following -- --thresholds | --epsilon`
//! prints the scans behind them.

mod common;

use planner::PlannerKind;
use planner::params::PlannerParams;

/// Lane-centring tolerance: a path's lateral equilibrium stays this close to where it is
/// without the neighbour (m).
const LANE_CENTRING_TOLERANCE_M: f64 = 0.05;

/// A vehicle in the other lane may change a planned speed by at most this (m/s): the speed
/// drop the metrics count as slowing.
const SPEED_TOLERANCE_MPS: f64 = 0.1;

#[test]
fn path_field_epsilon_is_the_largest_1_2_5_value_that_keeps_a_vehicle_alongside_out_of_the_lane() {
    let base = PlannerParams::default();
    let alone = common::lateral_equilibrium_m(&base, None);
    let shift = |epsilon: f64| {
        let params = PlannerParams {
            obstacle_epsilon: epsilon,
            ..base.clone()
        };
        (common::lateral_equilibrium_m(&params, Some((0.0, 1.75))) - alone).abs()
    };
    assert!(
        shift(base.obstacle_epsilon) <= LANE_CENTRING_TOLERANCE_M,
        "{}",
        shift(base.obstacle_epsilon)
    );
    // The next value of the 1–2–5 series breaks the tolerance.
    let next = 2.0 * base.obstacle_epsilon;
    assert!(shift(next) > LANE_CENTRING_TOLERANCE_M, "{}", shift(next));
}

#[test]
fn interaction_epsilon_is_the_largest_1_2_5_value_that_leaves_a_speed_alone_for_the_other_lane() {
    let base = PlannerParams::default();
    let alone = common::first_planned_speed_mps(PlannerKind::PfIsoPred, &base, None);
    let change = |epsilon: f64| {
        let params = PlannerParams {
            interaction_epsilon: epsilon,
            ..base.clone()
        };
        [1.0, 5.0, 10.0, 20.0, 30.0]
            .iter()
            .map(|ahead| {
                (common::first_planned_speed_mps(PlannerKind::PfIsoPred, &params, Some(*ahead))
                    - alone)
                    .abs()
            })
            .fold(0.0, f64::max)
    };
    let at_default = change(base.interaction_epsilon);
    assert!(at_default <= SPEED_TOLERANCE_MPS, "{at_default}");
    let next = change(2.0 * base.interaction_epsilon);
    assert!(next > SPEED_TOLERANCE_MPS, "{next}");
}

#[test]
fn risk_and_interaction_weights_are_twice_the_smallest_that_keep_a_follower_behind() {
    let base = PlannerParams::default();
    for (kind, weight) in [
        (PlannerKind::PfSp, base.risk_weight),
        (PlannerKind::PfIsoPred, base.interaction_weight),
    ] {
        let smallest = common::smallest_following_weight(kind, &base, 1.0, 400.0);
        assert!(
            (weight - (2.0 * smallest).round()).abs() <= 1.0,
            "{kind}: weight {weight}, smallest that keeps behind {smallest:.2}"
        );
        // Half the weight lets the follower run into the leader.
        let half = PlannerParams {
            risk_weight: 0.45 * weight,
            interaction_weight: 0.45 * weight,
            ..base.clone()
        };
        assert!(!common::keeps_behind(kind, &half), "{kind}");
    }
}

#[test]
fn with_its_weight_the_pf_sp_follower_settles_near_its_field_s_safety_distance() {
    let base = PlannerParams::default();
    let d_min = common::equal_speed_min_distance_m(15.0, base.obstacle_time_gap_s);
    let (gap, speed, min_gap) = common::following(PlannerKind::PfSp, &base, 15.0, 60.0, 60.0);
    assert!((speed - 15.0).abs() < 0.1, "{speed}");
    assert!(
        gap > 0.8 * d_min && gap < 1.3 * d_min,
        "gap {gap:.1} m, D_min {d_min:.1} m"
    );
    assert!(min_gap > 0.8 * d_min, "{min_gap}");
}

#[test]
fn the_shared_path_covers_eight_seconds() {
    // The horizon of Baidu Apollo's EM planner (Fan et al. 2018: "at least 8 s or 200 m").
    let p = PlannerParams::default();
    assert_eq!(p.waypoint_count as f64 * p.step_time_s, 8.0);
}
