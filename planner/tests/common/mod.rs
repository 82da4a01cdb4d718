//! Kinematic roll-outs shared by the planner's calibration tests and examples: vehicles moved
//! exactly along their own timed plans (`Plan::kinematic_state_at`), no tracker, no tyres.
#![allow(dead_code)]

use mergesim_types::{MergeRoad, Neighbour, SharedLocalPath, VehicleShape, VehicleState};
use planner::params::PlannerParams;
use planner::{PfPlanner, PlanRequest, PlannerKind};

/// A road whose merge section ends at x = 50 m: from there on one lane (the upper one), so a
/// follower cannot overtake.
pub fn single_lane_road() -> MergeRoad {
    MergeRoad {
        merge_start_x_m: 0.0,
        merge_end_x_m: 50.0,
        start_x_m: -100.0,
        end_x_m: 5000.0,
        ..MergeRoad::default()
    }
}

/// Car following on [`single_lane_road`]: a leader at `leader_speed_mps` straight on the lane
/// centre starting `initial_gap_m` ahead of a follower at 20 m/s (target 20 m/s) planning with
/// `kind` and `params`, replanning every 0.1 s for `duration_s`. Returns the centre-to-centre
/// gap at the end, the follower's speed then, and the smallest gap over the run.
pub fn following(
    kind: PlannerKind,
    params: &PlannerParams,
    leader_speed_mps: f64,
    initial_gap_m: f64,
    duration_s: f64,
) -> (f64, f64, f64) {
    let road = single_lane_road();
    let shape = VehicleShape::default();
    let mut planner = PfPlanner::new(kind, params.clone(), road.lane_road().unwrap()).unwrap();
    let y_m = road.lane_center_y_m(mergesim_types::Lane::Upper);
    let mut follower = VehicleState {
        x_m: 100.0,
        y_m,
        yaw_rad: 0.0,
        speed_mps: 20.0,
    };
    let step_s = 0.1;
    let steps = (duration_s / step_s).round() as usize;
    let leader_at = |t_s: f64| VehicleState {
        x_m: 100.0 + initial_gap_m + leader_speed_mps * t_s,
        y_m,
        yaw_rad: 0.0,
        speed_mps: leader_speed_mps,
    };
    let mut min_gap_m = initial_gap_m;
    for k in 0..steps {
        let t_s = k as f64 * step_s;
        let leader = leader_at(t_s);
        min_gap_m = min_gap_m.min(leader.x_m - follower.x_m);
        // The leader's shared path: straight at its constant speed (for PF-ISO).
        let shared = SharedLocalPath {
            vehicle_id: 1,
            stamp_s: t_s,
            shape,
            speed_mps: leader_speed_mps,
            waypoints: (0..=params.waypoint_count)
                .map(|i| {
                    let dt = i as f64 * params.step_time_s;
                    let s = leader_at(t_s + dt);
                    mergesim_types::TimedWaypoint {
                        t_s: t_s + dt,
                        x_m: s.x_m,
                        y_m: s.y_m,
                    }
                })
                .collect(),
        };
        let neighbours = [Neighbour {
            id: 1,
            state: leader,
            shape,
        }];
        let request = PlanRequest {
            time_s: t_s,
            ego_id: 0,
            ego: follower,
            ego_shape: shape,
            target_speed_mps: 20.0,
            mu: 0.8,
            neighbours: &neighbours,
            shared_paths: std::slice::from_ref(&shared),
        };
        let plan = planner.plan(&request).unwrap();
        follower = plan.kinematic_state_at(&follower, t_s + step_s);
    }
    let leader = leader_at(steps as f64 * step_s);
    let gap_m = leader.x_m - follower.x_m;
    (gap_m, follower.speed_mps, min_gap_m.min(gap_m))
}

/// Whether a follower planning with `kind` and `params` stays behind a leader at 15 m/s (60 m
/// ahead at the start) on a single lane for 60 s without the bodies touching.
pub fn keeps_behind(kind: PlannerKind, params: &PlannerParams) -> bool {
    let (_, _, min_gap_m) = following(kind, params, 15.0, 60.0, 60.0);
    min_gap_m > VehicleShape::default().length_m
}

/// The smallest weight (w_R for PF-SP, w3 otherwise) with which the follower keeps behind,
/// by bisection over [lo, hi] to a relative precision of 1 %.
pub fn smallest_following_weight(kind: PlannerKind, base: &PlannerParams, lo: f64, hi: f64) -> f64 {
    try_smallest_following_weight(kind, base, lo, hi).expect("bracket")
}

/// [`smallest_following_weight`], or None when [lo, hi] does not bracket it (the follower
/// keeps behind already at `lo`, or not even at `hi`).
pub fn try_smallest_following_weight(
    kind: PlannerKind,
    base: &PlannerParams,
    lo: f64,
    hi: f64,
) -> Option<f64> {
    let with = |w: f64| PlannerParams {
        risk_weight: w,
        interaction_weight: w,
        ..base.clone()
    };
    let (mut lo, mut hi) = (lo, hi);
    if keeps_behind(kind, &with(lo)) || !keeps_behind(kind, &with(hi)) {
        return None;
    }
    while hi / lo > 1.01 {
        let mid = (lo * hi).sqrt();
        if keeps_behind(kind, &with(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// D_min of a follower behind a leader at the same speed `v` (the braking terms cancel):
/// the body length + v·τ.
pub fn equal_speed_min_distance_m(v_mps: f64, time_gap_s: f64) -> f64 {
    VehicleShape::default().length_m + v_mps * time_gap_s
}

/// Lateral equilibrium of the path field (F_y = 0, by bisection) near the upper lane's centre
/// at x = 100 m on the default road, with `neighbour_y_m` the lateral position of a vehicle at
/// the same speed `ahead_m` in front (None: no neighbour).
pub fn lateral_equilibrium_m(params: &PlannerParams, neighbour: Option<(f64, f64)>) -> f64 {
    let road = MergeRoad::default();
    let shape = VehicleShape::default();
    let centre = road.lane_center_y_m(mergesim_types::Lane::Upper);
    let ego = VehicleState {
        x_m: 100.0,
        y_m: centre,
        yaw_rad: 0.0,
        speed_mps: 20.0,
    };
    let neighbours: Vec<Neighbour> = neighbour
        .map(|(ahead_m, y_m)| Neighbour {
            id: 1,
            state: VehicleState {
                x_m: 100.0 + ahead_m,
                y_m,
                yaw_rad: 0.0,
                speed_mps: 20.0,
            },
            shape,
        })
        .into_iter()
        .collect();
    let geometry = planner::lane_road_field::LaneRoadGeometry::new(&road.lane_road().unwrap());
    let field = planner::potential_field::PotentialField::new(
        &planner::potential_field::UniversalFieldParams::from(params),
        &geometry,
        0,
        &ego,
        &shape,
        &neighbours,
    );
    let fy = |y: f64| field.stepping_force(100.0, y)[1];
    let (mut lo, mut hi) = (centre - 1.0, centre + 1.0);
    assert!(fy(lo) > 0.0 && fy(hi) < 0.0, "restoring on both sides");
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if fy(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    lo
}

/// The first planned speed of a vehicle at 20 m/s (target 20) on the lower lane's centre of the
/// default road at x = 20 m, with a vehicle at 20 m/s on the upper lane's centre `ahead_m` in
/// front of it (None: alone).
pub fn first_planned_speed_mps(
    kind: PlannerKind,
    params: &PlannerParams,
    ahead_m: Option<f64>,
) -> f64 {
    let road = MergeRoad::default();
    let shape = VehicleShape::default();
    let mut planner = PfPlanner::new(kind, params.clone(), road.lane_road().unwrap()).unwrap();
    let ego = VehicleState {
        x_m: 20.0,
        y_m: road.lane_center_y_m(mergesim_types::Lane::Lower),
        yaw_rad: 0.0,
        speed_mps: 20.0,
    };
    let neighbours: Vec<Neighbour> = ahead_m
        .map(|ahead| Neighbour {
            id: 1,
            state: VehicleState {
                x_m: 20.0 + ahead,
                y_m: road.lane_center_y_m(mergesim_types::Lane::Upper),
                yaw_rad: 0.0,
                speed_mps: 20.0,
            },
            shape,
        })
        .into_iter()
        .collect();
    let request = PlanRequest {
        time_s: 0.0,
        ego_id: 0,
        ego,
        ego_shape: shape,
        target_speed_mps: 20.0,
        mu: 0.8,
        neighbours: &neighbours,
        shared_paths: &[],
    };
    let plan = planner.plan(&request).unwrap();
    plan.path
        .iter()
        .map(|p| p.speed_mps)
        .fold(f64::NAN, |acc, v| {
            if acc.is_nan() || (v - 20.0).abs() > (acc - 20.0).abs() {
                v
            } else {
                acc
            }
        })
}
