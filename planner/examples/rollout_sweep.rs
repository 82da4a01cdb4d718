//! Kinematic roll-out of the urgent merge with the obstacle's start swept from 25 to 80 m.
//!
//! The same roll-out as the test `ego_leaves_the_ending_lane_before_the_edge_closes_in` in
//! `tests/planners.rs`: ego at x = 0 m in the ending lane at 20 m/s, obstacle in the through
//! lane at 15 m/s, both with the default planner parameters, replanning every 0.1 s for 20 s,
//! ideal V2V (each receives the other's latest shared local path), and each vehicle moved along
//! its own timed plan (`Plan::kinematic_state_at`: no tracker, no tyres). For every obstacle
//! start and planner kind it prints when and where (ego x) the two bodies (oriented rectangles)
//! first overlap, if ever, where the ego's centre crosses the divider and how far ahead (+) or
//! behind (−) of the obstacle's centre, the ego's minimum and maximum speeds, the obstacle's
//! minimum speed, and the number of fallback plans.
//!
//! `cargo run --release -p planner --example rollout_sweep`

use mergesim_types::{Lane, MergeRoad, Neighbour, SharedLocalPath, VehicleShape, VehicleState};
use planner::params::PlannerParams;
use planner::{PfPlanner, PlanRequest, PlannerKind};

/// Replanning period and roll-out length (s).
const STEP_S: f64 = 0.1;
const STEPS: usize = 200;

/// Corners of a vehicle's body rectangle (world frame).
fn corners(s: &VehicleState, shape: &VehicleShape) -> [[f64; 2]; 4] {
    let (sin, cos) = s.yaw_rad.sin_cos();
    let (hl, hw) = (0.5 * shape.length_m, 0.5 * shape.width_m);
    [(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)]
        .map(|(u, v)| [s.x_m + u * cos - v * sin, s.y_m + u * sin + v * cos])
}

/// Separating-axis test of two oriented rectangles.
fn bodies_overlap(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4]) -> bool {
    let edge = |p: [f64; 2], q: [f64; 2]| [p[0] - q[0], p[1] - q[1]];
    let axes = [
        edge(a[1], a[0]),
        edge(a[3], a[0]),
        edge(b[1], b[0]),
        edge(b[3], b[0]),
    ];
    let project = |r: &[[f64; 2]; 4], n: [f64; 2]| {
        r.iter()
            .map(|p| p[0] * n[0] + p[1] * n[1])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            })
    };
    axes.into_iter().all(|n| {
        let ((a_lo, a_hi), (b_lo, b_hi)) = (project(a, n), project(b, n));
        a_lo <= b_hi && b_lo <= a_hi
    })
}

/// What one roll-out gives.
struct Outcome {
    /// Time and ego x of the first overlap of the bodies (s, m).
    first_overlap: Option<(f64, f64)>,
    /// Ego x at the divider and ego x − obstacle x then (m).
    crossing_m: Option<(f64, f64)>,
    ego_min_speed_mps: f64,
    ego_max_speed_mps: f64,
    obstacle_min_speed_mps: f64,
    fallbacks: usize,
}

fn roll_out(kind: PlannerKind, obstacle_x_m: f64) -> Result<Outcome, Box<dyn std::error::Error>> {
    let road = MergeRoad::default();
    let shape = VehicleShape::default();
    let new = || {
        PfPlanner::new(
            kind,
            PlannerParams::default(),
            road.lane_road().expect("valid road"),
        )
    };
    let mut planners = [new()?, new()?];
    let y_lower_m = road.lane_center_y_m(Lane::Lower);
    let y_upper_m = road.lane_center_y_m(Lane::Upper);
    let mut states =
        [(0.0, y_lower_m, 20.0), (obstacle_x_m, y_upper_m, 15.0)].map(|(x_m, y_m, speed_mps)| {
            VehicleState {
                x_m,
                y_m,
                yaw_rad: 0.0,
                speed_mps,
            }
        });
    let targets_mps = [20.0, 15.0];
    let mut shared: Vec<SharedLocalPath> = Vec::new();
    let mut out = Outcome {
        first_overlap: None,
        crossing_m: None,
        ego_min_speed_mps: f64::INFINITY,
        ego_max_speed_mps: 0.0,
        obstacle_min_speed_mps: f64::INFINITY,
        fallbacks: 0,
    };
    for step in 0..STEPS {
        let t_s = STEP_S * step as f64;
        let mut plans = Vec::with_capacity(2);
        for (i, planner) in planners.iter_mut().enumerate() {
            let neighbours = [Neighbour {
                id: (1 - i) as u32,
                state: states[1 - i],
                shape,
            }];
            let plan = planner.plan(&PlanRequest {
                time_s: t_s,
                ego_id: i as u32,
                ego: states[i],
                ego_shape: shape,
                target_speed_mps: targets_mps[i],
                mu: 0.8,
                neighbours: &neighbours,
                shared_paths: &shared,
            })?;
            out.fallbacks += usize::from(plan.fallback.is_some());
            plans.push(plan);
        }
        shared = plans.iter().map(|p| p.shared.clone()).collect();
        for (state, plan) in states.iter_mut().zip(&plans) {
            *state = plan.kinematic_state_at(state, t_s + STEP_S);
        }
        let [ego, obstacle] = states;
        out.ego_min_speed_mps = out.ego_min_speed_mps.min(ego.speed_mps);
        out.ego_max_speed_mps = out.ego_max_speed_mps.max(ego.speed_mps);
        out.obstacle_min_speed_mps = out.obstacle_min_speed_mps.min(obstacle.speed_mps);
        if out.first_overlap.is_none()
            && bodies_overlap(&corners(&ego, &shape), &corners(&obstacle, &shape))
        {
            out.first_overlap = Some((t_s + STEP_S, ego.x_m));
        }
        if out.crossing_m.is_none() && ego.y_m > road.y_lane_m() {
            out.crossing_m = Some((ego.x_m, ego.x_m - obstacle.x_m));
        }
    }
    Ok(out)
}

/// Both numbers with one decimal (the second with its sign if `signed`), or two dashes.
fn pair(v: Option<(f64, f64)>, signed: bool) -> (String, String) {
    v.map_or(("-".into(), "-".into()), |(a, b)| {
        let b = if signed {
            format!("{b:+.1}")
        } else {
            format!("{b:.1}")
        };
        (format!("{a:.1}"), b)
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "obstacle_x0_m  planner      overlap_t_s  overlap_x_m  ego_cross_x_m  ego_ahead_m  \
         ego_v_min_mps  ego_v_max_mps  obstacle_v_min_mps  fallbacks"
    );
    for obstacle_x_m in (25..=80).map(f64::from) {
        for kind in PlannerKind::ALL {
            let o = roll_out(kind, obstacle_x_m)?;
            let (overlap_t, overlap_x) = pair(o.first_overlap, false);
            let (cross_x, ahead) = pair(o.crossing_m, true);
            println!(
                "{obstacle_x_m:13.0}  {:<11}  {overlap_t:>11}  {overlap_x:>11}  {cross_x:>13}  \
                 {ahead:>11}  {:13.2}  {:13.2}  {:18.2}  {:9}",
                kind.name(),
                o.ego_min_speed_mps,
                o.ego_max_speed_mps,
                o.obstacle_min_speed_mps,
                o.fallbacks
            );
        }
    }
    Ok(())
}
