//! Stop and go at the planner: cycles at standstill, and kinematic roll-outs behind a car that
//! stops and drives off again, for every planner in both parameter sets.

use super::*;
use crate::parameter_set::ParameterSet;
use crate::params::PlannerParams;
use crate::planner_kind::PlannerKind;
use crate::planners::PfPlanner;
use mergesim_types::{
    Lane, MergeRoad, Neighbour, SharedLocalPath, TimedWaypoint, VehicleShape, VehicleState,
};

/// The merge road with its merge section ending at x = 50 m: one lane (the upper) beyond, so
/// nobody can pass the stopped car.
fn single_lane_road() -> MergeRoad {
    MergeRoad {
        merge_start_x_m: 0.0,
        merge_end_x_m: 50.0,
        start_x_m: -100.0,
        end_x_m: 3000.0,
        ..MergeRoad::default()
    }
}

fn lane_y_m() -> f64 {
    single_lane_road().lane_center_y_m(Lane::Upper)
}

fn at(x_m: f64, speed_mps: f64) -> VehicleState {
    VehicleState {
        x_m,
        y_m: lane_y_m(),
        yaw_rad: 0.0,
        speed_mps,
    }
}

fn planner(kind: PlannerKind, params: &PlannerParams) -> PfPlanner {
    PfPlanner::new(
        kind,
        params.clone(),
        single_lane_road().lane_road().unwrap(),
    )
    .unwrap()
}

/// One cycle of `kind` at `ego` with `neighbours` (their straight shared paths at their
/// speeds, for PF-ISO).
fn plan_once(
    planner: &mut PfPlanner,
    time_s: f64,
    ego: VehicleState,
    neighbours: &[Neighbour],
    shared: &[SharedLocalPath],
) -> crate::Plan {
    planner
        .plan(&PlanRequest {
            time_s,
            ego_id: 0,
            ego,
            ego_shape: VehicleShape::default(),
            target_speed_mps: 12.0,
            mu: 0.8,
            neighbours,
            shared_paths: shared,
        })
        .unwrap()
}

fn leader(state: VehicleState) -> Neighbour {
    Neighbour {
        id: 1,
        state,
        shape: VehicleShape::default(),
    }
}

fn assert_finite_and_non_negative(plan: &crate::Plan, what: &str) {
    for p in &plan.path {
        assert!(
            p.x_m.is_finite() && p.y_m.is_finite() && p.t_s.is_finite(),
            "{what}: {p:?}"
        );
        assert!(
            p.speed_mps.is_finite() && p.speed_mps >= 0.0,
            "{what}: {p:?}"
        );
    }
    for w in plan.path.windows(2) {
        assert!(w[1].t_s >= w[0].t_s, "{what}: times must not run back");
    }
    assert!(
        plan.shared
            .waypoints
            .iter()
            .all(|w| w.t_s.is_finite() && w.x_m.is_finite() && w.y_m.is_finite()),
        "{what}"
    );
}

#[test]
fn at_standstill_behind_a_stopped_car_every_planner_plans_finite_speeds_down_to_zero() {
    let length_m = VehicleShape::default().length_m;
    for set in ParameterSet::ALL {
        let params = set.planner_params();
        let s0 = params.following_standstill_gap_m;
        for kind in PlannerKind::ALL {
            let what = format!("{} / {}", set.name(), kind.name());
            // At the stop point: the bumper gap is s₀; every speed is 0.
            let ego = at(200.0, 0.0);
            let ahead = [leader(at(200.0 + length_m + s0, 0.0))];
            let plan = plan_once(&mut planner(kind, &params), 0.0, ego, &ahead, &[]);
            assert_finite_and_non_negative(&plan, &what);
            assert!(plan.fallback.is_none(), "{what}: {:?}", plan.fallback);
            assert!(
                plan.path.iter().all(|p| p.speed_mps < 1e-9),
                "{what}: {:?}",
                plan.path
            );
            // 0.3 m short of it: below v_min, at Gipps' speed for the 0.3 m left.
            let ahead = [leader(at(200.0 + length_m + s0 + 0.3, 0.0))];
            let plan = plan_once(&mut planner(kind, &params), 0.0, ego, &ahead, &[]);
            assert_finite_and_non_negative(&plan, &what);
            let cap = crate::following::safe_following_speed_mps(&(&params).into(), s0 + 0.3, 0.0);
            assert!(cap < params.min_speed_mps, "{cap}");
            assert!(
                plan.path.iter().all(|p| p.speed_mps <= cap + 1e-12),
                "{what}: {:?}",
                plan.path
            );
        }
    }
}

#[test]
fn at_standstill_on_a_free_road_the_planned_speed_rises() {
    for set in ParameterSet::ALL {
        let params = set.planner_params();
        for kind in PlannerKind::ALL {
            let what = format!("{} / {}", set.name(), kind.name());
            let plan = plan_once(&mut planner(kind, &params), 0.0, at(200.0, 0.0), &[], &[]);
            assert_finite_and_non_negative(&plan, &what);
            assert!(plan.fallback.is_none(), "{what}");
            assert!(plan.path[1].speed_mps > 0.4, "{what}: {:?}", plan.path);
            let last = plan.path.last().map_or(0.0, |p| p.speed_mps);
            assert!(last >= plan.path[1].speed_mps, "{what}: {:?}", plan.path);
        }
    }
}

#[test]
fn moving_traffic_has_no_stop_and_go_caps() {
    let params = PlannerParams::default();
    let road =
        crate::lane_road_field::LaneRoadGeometry::new(&single_lane_road().lane_road().unwrap());
    let points: Vec<[f64; 2]> = (1..=20)
        .map(|i| [200.0 + 5.0 * i as f64, lane_y_m()])
        .collect();
    let request = |ego_speed_mps: f64, neighbours: &[Neighbour]| {
        let req = PlanRequest {
            time_s: 0.0,
            ego_id: 0,
            ego: at(200.0, ego_speed_mps),
            ego_shape: VehicleShape::default(),
            target_speed_mps: 12.0,
            mu: 0.8,
            neighbours,
            shared_paths: &[],
        };
        stop_and_go_caps_mps(&(&params).into(), &road, &req, &points, false)
    };
    let fast = [leader(at(240.0, 10.0))];
    assert_eq!(request(12.0, &fast), None);
    let slow = [leader(at(240.0, 3.0))];
    let caps = request(12.0, &slow).unwrap();
    assert_eq!(caps.len(), params.waypoint_count);
    // A slow ego with a faster car ahead: caps, but above the car's speed, far above the ego's.
    let caps = request(1.0, &fast).unwrap();
    assert!(caps.iter().all(|c| *c > 10.0), "{caps:?}");
    // Off with the threshold at 0.
    let off = PlannerParams {
        stop_and_go_speed_mps: 0.0,
        ..params.clone()
    };
    let req = PlanRequest {
        time_s: 0.0,
        ego_id: 0,
        ego: at(200.0, 12.0),
        ego_shape: VehicleShape::default(),
        target_speed_mps: 12.0,
        mu: 0.8,
        neighbours: &slow,
        shared_paths: &[],
    };
    assert_eq!(
        stop_and_go_caps_mps(&(&off).into(), &road, &req, &points, true),
        None
    );
    // Once on, it stays on while the car ahead holds it below V_target (12 m/s), ...
    let close = [leader(at(215.0, 10.0))];
    let req = PlanRequest {
        neighbours: &close,
        ..req
    };
    assert!(stop_and_go_caps_mps(&(&params).into(), &road, &req, &points, true).is_some());
    assert_eq!(
        stop_and_go_caps_mps(&(&params).into(), &road, &req, &points, false),
        None
    );
    // ... and ends when it no longer does.
    let gone = [leader(at(400.0, 10.0))];
    let req = PlanRequest {
        neighbours: &gone,
        ..req
    };
    assert_eq!(
        stop_and_go_caps_mps(&(&params).into(), &road, &req, &points, true),
        None
    );
}

/// Kinematic roll-out (the vehicle moved exactly along its timed plans, replanning every
/// 0.1 s): the ego at 12 m/s, 60 m behind a car standing until 25 s (PF-SP's risk term
/// slows it early, then it covers the last metres at v_min), which then
/// accelerates at 2 m/s² to 10 m/s. Returns (smallest bumper gap (m), ego speed at
/// `restart_s` (m/s), distance the ego moved over the 3 s before `restart_s` (m), ego speed
/// 8 s after `restart_s` (m/s)).
fn roll_out(kind: PlannerKind, params: &PlannerParams) -> (f64, f64, f64, f64) {
    let length_m = VehicleShape::default().length_m;
    let restart_s = 25.0;
    let leader_x0_m = 260.0;
    let leader_at = |t_s: f64| {
        let tau = (t_s - restart_s).max(0.0);
        let (x, v) = if tau < 5.0 {
            (tau * tau, 2.0 * tau)
        } else {
            (25.0 + 10.0 * (tau - 5.0), 10.0)
        };
        at(leader_x0_m + x, v)
    };
    let mut planner = planner(kind, params);
    let mut ego = at(200.0, 12.0);
    let step_s = 0.1;
    let mut min_gap_m = f64::INFINITY;
    let (mut speed_at_restart, mut x_before, mut moved_m) = (f64::NAN, f64::NAN, f64::NAN);
    for k in 0..=((restart_s + 8.0) / step_s).round() as usize {
        let t_s = k as f64 * step_s;
        let lead = leader_at(t_s);
        min_gap_m = min_gap_m.min(lead.x_m - ego.x_m - length_m);
        if k == ((restart_s - 3.0) / step_s).round() as usize {
            x_before = ego.x_m;
        }
        if k == (restart_s / step_s).round() as usize {
            speed_at_restart = ego.speed_mps;
            moved_m = (ego.x_m - x_before).abs();
        }
        let shared = SharedLocalPath {
            vehicle_id: 1,
            stamp_s: t_s,
            shape: VehicleShape::default(),
            speed_mps: lead.speed_mps,
            waypoints: (0..=params.waypoint_count)
                .map(|i| {
                    let t = t_s + i as f64 * params.step_time_s;
                    // Standing, it does not announce when it will start.
                    let s = if t_s < restart_s { lead } else { leader_at(t) };
                    TimedWaypoint {
                        t_s: t,
                        x_m: s.x_m,
                        y_m: s.y_m,
                    }
                })
                .collect(),
        };
        let plan = plan_once(&mut planner, t_s, ego, &[leader(lead)], &[shared]);
        assert_finite_and_non_negative(&plan, kind.name());
        if std::env::var("SG_DEBUG").is_ok() && k % 5 == 0 {
            eprintln!(
                "{} t {t_s:.1} x {:.2} v {:.2} gap {:.2} fb {:?} v1 {:.3} y_end {:.2}",
                kind.name(),
                ego.x_m,
                ego.speed_mps,
                lead.x_m - ego.x_m - length_m,
                plan.fallback.is_some(),
                plan.path[1].speed_mps,
                plan.path.last().map_or(0.0, |p| p.y_m)
            );
        }
        // Moved along the timed plan; its speed the distance over the step (the plan's own
        // speed interpolation over a first segment that lasts 100 s at standstill would lag).
        let next = plan.kinematic_state_at(&ego, t_s + step_s);
        let speed_mps = (next.x_m - ego.x_m).hypot(next.y_m - ego.y_m) / step_s;
        ego = VehicleState { speed_mps, ..next };
    }
    (min_gap_m, speed_at_restart, moved_m, ego.speed_mps)
}

#[test]
fn every_planner_stops_behind_a_stopped_car_stays_and_starts_again() {
    for set in ParameterSet::ALL {
        let params = set.planner_params();
        for kind in PlannerKind::ALL {
            let (min_gap_m, stopped_mps, moved_m, restarted_mps) = roll_out(kind, &params);
            let what = format!(
                "{} / {}: min gap {min_gap_m:.3} m, speed at restart {stopped_mps:.4} m/s, \
                 moved {moved_m:.4} m in 3 s, speed 8 s later {restarted_mps:.2} m/s",
                set.name(),
                kind.name()
            );
            eprintln!("{what}");
            assert!(min_gap_m >= 1.5, "{what}");
            assert!(stopped_mps < 0.1, "{what}");
            assert!(moved_m < 0.1, "{what}");
            assert!(restarted_mps > 3.0, "{what}");
        }
    }
}
