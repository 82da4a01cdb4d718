//! Behaviour of the planners through the public API.

use mergesim_types::{
    FallbackReason, Lane, MergeRoad, Neighbour, SharedLocalPath, TimedWaypoint, VehicleShape,
    VehicleState,
};
use planner::cubic_fit::CubicPath;
use planner::params::GRAVITY_MPS2;
use planner::params::PlannerParams;
use planner::{PfPlanner, Plan, PlanRequest, PlannerError, PlannerKind};

fn state(x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> VehicleState {
    VehicleState {
        x_m,
        y_m,
        yaw_rad,
        speed_mps,
    }
}

fn request<'a>(
    ego: VehicleState,
    target_speed_mps: f64,
    neighbours: &'a [Neighbour],
    shared_paths: &'a [SharedLocalPath],
) -> PlanRequest<'a> {
    PlanRequest {
        time_s: 3.0,
        ego_id: 0,
        ego,
        ego_shape: VehicleShape::default(),
        target_speed_mps,
        mu: 0.8,
        neighbours,
        shared_paths,
    }
}

fn planner(kind: PlannerKind) -> PfPlanner {
    PfPlanner::new(
        kind,
        PlannerParams::default(),
        MergeRoad::default().lane_road().unwrap(),
    )
    .unwrap()
}

/// The simulator may run vehicles or Monte-Carlo runs on other threads.
#[test]
fn planner_is_send_and_sync() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<PfPlanner>();
    assert_send_sync::<Plan>();
}

#[test]
fn kind_names_round_trip_and_an_unknown_name_lists_the_valid_ones() {
    for kind in PlannerKind::ALL {
        assert_eq!(kind.name().parse::<PlannerKind>().unwrap(), kind);
        let json = serde_json::to_string(&kind).unwrap();
        assert_eq!(json, format!("\"{}\"", kind.name()));
    }
    let err = "pf-magic".parse::<PlannerKind>().unwrap_err().to_string();
    for kind in PlannerKind::ALL {
        assert!(err.contains(kind.name()), "{err}");
    }
}

#[test]
fn plan_starts_at_the_vehicle_with_times_from_distance_over_speed() {
    let mut p = planner(PlannerKind::PfSp);
    let ego = state(20.0, 1.9, 0.01, 18.0);
    let plan = p.plan(&request(ego, 20.0, &[], &[])).unwrap();
    assert!(plan.fallback.is_none());
    let n = p.params().waypoint_count;
    assert_eq!(plan.waypoints.len(), n);
    assert_eq!(plan.path.len(), n + 1);
    assert_eq!(
        (plan.path[0].x_m, plan.path[0].y_m, plan.path[0].t_s),
        (20.0, 1.9, 3.0)
    );
    for w in plan.path.windows(2) {
        let ds = ((w[1].x_m - w[0].x_m).powi(2) + (w[1].y_m - w[0].y_m).powi(2)).sqrt();
        // Segment k is driven at the speed its end point carries; the first point carries the
        // vehicle's speed.
        assert!((w[1].t_s - w[0].t_s - ds / w[1].speed_mps).abs() < 1e-9);
    }
    // The broadcast carries the same timed points.
    assert_eq!(plan.shared.waypoints.len(), plan.path.len());
    for (s, p) in plan.shared.waypoints.iter().zip(&plan.path) {
        assert_eq!((s.t_s, s.x_m, s.y_m), (p.t_s, p.x_m, p.y_m));
    }
    // Waypoints spaced by L_s = v Δt_plan (Eq. 7).
    let ls = 18.0 * p.params().step_time_s;
    let first = plan.waypoints[0];
    let d = ((first[0] - 20.0).powi(2) + (first[1] - 1.9).powi(2)).sqrt();
    assert!((d - ls).abs() < 1e-9 || d < ls, "{d} vs {ls}");
}

/// The same request twice on fresh planners gives bit-identical plans.
#[test]
fn planning_is_deterministic() {
    let neighbours = [Neighbour {
        id: 1,
        state: state(40.0, 5.25, 0.0, 15.0),
        shape: VehicleShape::default(),
    }];
    let ego = state(30.0, 1.75, 0.0, 20.0);
    let a = planner(PlannerKind::PfIsoPred)
        .plan(&request(ego, 20.0, &neighbours, &[]))
        .unwrap();
    let b = planner(PlannerKind::PfIsoPred)
        .plan(&request(ego, 20.0, &neighbours, &[]))
        .unwrap();
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
}

/// Curvature from the plan's own cubic by the textbook formula κ = y''/(1 + y'²)^{3/2}, written
/// out here independently of the library's evaluation.
fn textbook_curvature(cubic: [f64; 4], scale_m: f64, xi_m: f64) -> f64 {
    let u = xi_m / scale_m;
    let d1 = (cubic[1] + 2.0 * cubic[2] * u + 3.0 * cubic[3] * u * u) / scale_m;
    let d2 = (2.0 * cubic[2] + 6.0 * cubic[3] * u) / (scale_m * scale_m);
    d2 / (1.0 + d1 * d1).powf(1.5)
}

#[test]
fn curvature_caps_the_speed_in_a_bend() {
    // A vehicle yawed 0.2 rad off the road. The waypoints run along the road; with a tight
    // heading bound the fitted path has to leave along the vehicle's heading and bend back.
    let ego = state(10.0, 1.75, 0.2, 25.0);
    let mut req = request(ego, 30.0, &[], &[]);
    req.mu = 0.3;
    let tight = PlannerParams {
        cubic_max_heading_rad: 0.02,
        ..PlannerParams::default()
    };
    let mut p = PfPlanner::new(
        PlannerKind::PfSp,
        tight,
        MergeRoad::default().lane_road().unwrap(),
    )
    .unwrap();
    let plan = p.plan(&req).unwrap();
    assert!(plan.fallback.is_none());
    let params = p.params().clone();
    let frame = CubicPath {
        origin_xy_m: [ego.x_m, ego.y_m],
        cos_yaw: ego.yaw_rad.cos(),
        sin_yaw: ego.yaw_rad.sin(),
        coefficients: plan.cubic,
        x_scale_m: plan.cubic_x_scale_m,
        method: planner::cubic_fit::FitMethod::Unconstrained,
    };
    let xis: Vec<f64> = plan
        .path
        .iter()
        .map(|q| frame.to_local([q.x_m, q.y_m])[0])
        .collect();
    let mut capped = 0;
    for k in 0..plan.path.len() - 1 {
        let kappa = textbook_curvature(plan.cubic, plan.cubic_x_scale_m, xis[k])
            .abs()
            .max(textbook_curvature(plan.cubic, plan.cubic_x_scale_m, xis[k + 1]).abs());
        let friction_limit = (req.mu * GRAVITY_MPS2 / kappa).sqrt();
        let v = plan.path[k + 1].speed_mps;
        assert!(
            v <= friction_limit + 1e-6,
            "segment {k}: {v} > {friction_limit}"
        );
        if friction_limit < params.speed_limit_mps - 1.0 {
            capped += 1;
        }
    }
    assert!(
        capped >= 3,
        "the bend must bind the friction limit ({capped} segments)"
    );
    let slowest = plan
        .path
        .iter()
        .map(|q| q.speed_mps)
        .fold(f64::INFINITY, f64::min);
    assert!(slowest < 0.8 * req.target_speed_mps, "{slowest}");
    assert!(p.last_stats().cubic_qp, "the heading bound must be active");
    // On the straight with the same μ the target speed is kept.
    let straight = planner(PlannerKind::PfSp)
        .plan(&PlanRequest {
            ego: state(10.0, 1.75, 0.0, 25.0),
            ..req
        })
        .unwrap();
    assert!(straight.path.iter().all(|q| q.speed_mps > 25.0 - 1e-6));
}

/// The planning vehicle drives the upper lane at its 15 m/s target. A faster vehicle (18 m/s)
/// draws level in the lower lane and its shared path cuts in just ahead. PF-ISO must choose
/// lower speeds than PF-SP; with the same vehicle's SLP staying in its lane, PF-ISO must match
/// PF-SP.
#[test]
fn pf_iso_slows_for_a_faster_vehicle_cutting_in_ahead() {
    let t0 = 3.0;
    let ego = state(100.0, 5.25, 0.0, 15.0);
    let other = state(100.0, 1.75, 0.0, 18.0);
    let slp = |cut_in: bool| SharedLocalPath {
        vehicle_id: 1,
        stamp_s: t0,
        shape: VehicleShape::default(),
        speed_mps: 18.0,
        waypoints: (0..=20)
            .map(|i| {
                let t = 0.25 * i as f64;
                // Smooth-step lane change between 1 s and 3 s.
                let f = ((t - 1.0) / 2.0).clamp(0.0, 1.0);
                let lateral = if cut_in {
                    3.5 * f * f * (3.0 - 2.0 * f)
                } else {
                    0.0
                };
                TimedWaypoint {
                    t_s: t0 + t,
                    x_m: 100.0 + 18.0 * t,
                    y_m: 1.75 + lateral,
                }
            })
            .collect(),
    };
    let neighbours = [Neighbour {
        id: 1,
        state: other,
        shape: VehicleShape::default(),
    }];
    let speeds = |kind: PlannerKind, cut_in: bool| -> Vec<f64> {
        let shared = [slp(cut_in)];
        let mut req = request(ego, 15.0, &neighbours, &shared);
        req.time_s = t0;
        let plan = planner(kind).plan(&req).unwrap();
        assert!(plan.fallback.is_none());
        plan.path.iter().map(|p| p.speed_mps).collect()
    };
    let sp = speeds(PlannerKind::PfSp, true);
    let iso = speeds(PlannerKind::PfIso, true);
    let iso_no_cut = speeds(PlannerKind::PfIso, false);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        mean(&iso) < mean(&sp) - 0.3,
        "ISO {:.2} vs SP {:.2}: {iso:?}",
        mean(&iso),
        mean(&sp)
    );
    assert!(
        iso.iter().zip(&sp).all(|(a, b)| *a <= b + 1e-6),
        "{iso:?} vs {sp:?}"
    );
    assert!(
        (mean(&iso_no_cut) - mean(&sp)).abs() < 0.05,
        "no cut-in: ISO {:.3} vs SP {:.3}",
        mean(&iso_no_cut),
        mean(&sp)
    );
}

/// A faster vehicle closing in from 25 m behind in the same lane (17 vs 15 m/s, still 15 m
/// behind at the horizon): when the follower is responsible for the gap — roles fixed from the
/// order now (the default, for predicted vehicles), or per time slot with
/// `interaction_rear_only` — the leader keeps the speeds of Eq. 10 without interaction
/// (PF-SP-EQ10); with neither rule, the follower's field drives the leader's speeds away from
/// them (which way is up to the non-convex term). That is what the rules exist to prevent.
#[test]
fn a_follower_does_not_push_the_leader_when_the_follower_is_responsible() {
    let ego = state(100.0, 5.25, 0.0, 15.0);
    let neighbours = [Neighbour {
        id: 1,
        state: state(75.0, 5.25, 0.0, 17.0),
        shape: VehicleShape::default(),
    }];
    let mean_speed = |kind: PlannerKind, rear_only: bool, from_order_now: bool| {
        let params = PlannerParams {
            interaction_rear_only: rear_only,
            roles_from_order_now: from_order_now,
            ..PlannerParams::default()
        };
        let plan = PfPlanner::new(kind, params, MergeRoad::default().lane_road().unwrap())
            .unwrap()
            .plan(&request(ego, 15.0, &neighbours, &[]))
            .unwrap();
        plan.path.iter().map(|p| p.speed_mps).sum::<f64>() / plan.path.len() as f64
    };
    let free = mean_speed(PlannerKind::PfSpEq10, true, true);
    for (rear_only, from_order_now) in [(true, true), (false, true), (true, false)] {
        let leader = mean_speed(PlannerKind::PfIsoPred, rear_only, from_order_now);
        assert!(
            (leader - free).abs() < 0.05,
            "rear-only {rear_only}, order now {from_order_now}: {leader} vs {free}"
        );
    }
    let pushed = mean_speed(PlannerKind::PfIsoPred, false, false);
    assert!(
        (pushed - free).abs() > 0.3,
        "without either rule {pushed} vs PF-SP-EQ10 {free}"
    );
}

/// PF-ISO without a (fresh) SLP of a neighbour predicts it at constant velocity, exactly as
/// PF-ISO-PRED does.
#[test]
fn pf_iso_without_fresh_shared_paths_equals_pf_iso_pred() {
    let ego = state(100.0, 5.25, 0.0, 15.0);
    let other = state(98.0, 1.9, 0.05, 19.0);
    let neighbours = [Neighbour {
        id: 1,
        state: other,
        shape: VehicleShape::default(),
    }];
    let pred = planner(PlannerKind::PfIsoPred)
        .plan(&request(ego, 15.0, &neighbours, &[]))
        .unwrap();
    let none = planner(PlannerKind::PfIso)
        .plan(&request(ego, 15.0, &neighbours, &[]))
        .unwrap();
    assert_eq!(pred.path, none.path);
    // A stale SLP (older than max_shared_path_age_s) is ignored.
    let stale = SharedLocalPath {
        vehicle_id: 1,
        stamp_s: 3.0 - 2.0 * PlannerParams::default().max_shared_path_age_s,
        shape: VehicleShape::default(),
        speed_mps: 19.0,
        waypoints: vec![TimedWaypoint {
            t_s: 2.0,
            x_m: 120.0,
            y_m: 5.25,
        }],
    };
    let shared = [stale];
    let with_stale = planner(PlannerKind::PfIso)
        .plan(&request(ego, 15.0, &neighbours, &shared))
        .unwrap();
    assert_eq!(pred.path, with_stale.path);
    // And the interaction term really is in PF-ISO-PRED (it differs from PF-SP here).
    let sp = planner(PlannerKind::PfSp)
        .plan(&request(ego, 15.0, &neighbours, &[]))
        .unwrap();
    assert_ne!(pred.path, sp.path);
}

#[test]
fn solver_failure_returns_a_flagged_comfortable_deceleration() {
    let params = PlannerParams {
        solver_max_iterations: 0,
        ..PlannerParams::default()
    };
    let mut p = PfPlanner::new(
        PlannerKind::PfIso,
        params.clone(),
        MergeRoad::default().lane_road().unwrap(),
    )
    .unwrap();
    let ego = state(50.0, 1.75, 0.0, 20.0);
    let plan = p.plan(&request(ego, 20.0, &[], &[])).unwrap();
    let Some(FallbackReason::SolverFailed(text)) = &plan.fallback else {
        panic!(
            "expected a solver-failure fallback, got {:?}",
            plan.fallback
        );
    };
    assert!(text.contains("MaxIterations"), "{text}");
    assert!(p.last_stats().fallback);
    assert_eq!((plan.path[0].x_m, plan.path[0].y_m), (50.0, 1.75));
    // v(s)² = v0² − 2 a s along the path (kinematics of constant deceleration).
    let mut s = 0.0;
    for w in plan.path.windows(2) {
        s += ((w[1].x_m - w[0].x_m).powi(2) + (w[1].y_m - w[0].y_m).powi(2)).sqrt();
        let expected = (400.0 - 2.0 * params.fallback_decel_mps2 * s)
            .max(0.0)
            .sqrt();
        assert!((w[1].speed_mps - expected).abs() < 1e-9);
    }
    assert!(p.last_good_plan().is_none());
}

#[test]
fn fallback_follows_the_last_good_path() {
    let mut good = planner(PlannerKind::PfSp);
    let ego = state(50.0, 1.75, 0.0, 20.0);
    let first = good.plan(&request(ego, 20.0, &[], &[])).unwrap();
    let moved = state(first.path[2].x_m, first.path[2].y_m, 0.0, 20.0);
    let input = planner::fallback::FallbackInput {
        time_s: 3.5,
        ego_id: 0,
        ego: &moved,
        ego_shape: &VehicleShape::default(),
        last_good: good.last_good_plan(),
        waypoints: None,
    };
    let plan = planner::fallback::fallback_plan(
        good.params(),
        &input,
        FallbackReason::NonFinite("test".into()),
    );
    // After the vehicle's position come exactly the last plan's points ahead of it.
    for (a, b) in plan.path[1..].iter().zip(&first.path[3..]) {
        assert_eq!((a.x_m, a.y_m), (b.x_m, b.y_m));
    }
}

#[test]
fn non_finite_input_is_a_typed_error() {
    let mut p = planner(PlannerKind::PfIso);
    let bad = state(f64::NAN, 1.75, 0.0, 20.0);
    assert!(matches!(
        p.plan(&request(bad, 20.0, &[], &[])),
        Err(PlannerError::NonFinite { .. })
    ));
    let ego = state(0.0, 1.75, 0.0, 20.0);
    let neighbours = [Neighbour {
        id: 1,
        state: state(10.0, f64::INFINITY, 0.0, 15.0),
        shape: VehicleShape::default(),
    }];
    assert!(matches!(
        p.plan(&request(ego, 20.0, &neighbours, &[])),
        Err(PlannerError::NonFinite { .. })
    ));
    let mut req = request(ego, 20.0, &[], &[]);
    req.mu = -1.0;
    assert!(matches!(
        p.plan(&req),
        Err(PlannerError::InvalidParameter(_))
    ));
}

/// The paper's urgent merge rolled forward kinematically along the vehicles' own plans
/// (replanning every 0.1 s, V2V ideal): the ego must leave the ending lane before the lower
/// edge reaches its side, and settle in the through lane.
#[test]
fn ego_leaves_the_ending_lane_before_the_edge_closes_in() {
    let road = MergeRoad::default();
    for kind in PlannerKind::ALL {
        let mut planners = [planner(kind), planner(kind)];
        let mut states = [state(0.0, 1.75, 0.0, 20.0), state(25.0, 5.25, 0.0, 15.0)];
        let targets = [20.0, 15.0];
        let shape = VehicleShape::default();
        let mut shared: Vec<SharedLocalPath> = Vec::new();
        let mut crossed_at_x = None;
        let mut min_edge_clearance_m = f64::INFINITY;
        for step in 0..200 {
            let t_s = 0.1 * step as f64;
            let mut plans = Vec::new();
            for i in 0..2 {
                let neighbours = [Neighbour {
                    id: (1 - i) as u32,
                    state: states[1 - i],
                    shape,
                }];
                let req = PlanRequest {
                    time_s: t_s,
                    ego_id: i as u32,
                    ego: states[i],
                    ego_shape: shape,
                    target_speed_mps: targets[i],
                    mu: 0.8,
                    neighbours: &neighbours,
                    shared_paths: &shared,
                };
                let plan = planners[i].plan(&req).unwrap();
                assert!(plan.fallback.is_none(), "{kind}: fallback at {t_s}");
                plans.push(plan);
            }
            shared = plans.iter().map(|p| p.shared.clone()).collect();
            for i in 0..2 {
                states[i] = plans[i].kinematic_state_at(&states[i], t_s + 0.1);
            }
            let ego = states[0];
            let clearance = ego.y_m - 0.5 * shape.width_m - road.lower_edge_y_m(ego.x_m);
            min_edge_clearance_m = min_edge_clearance_m.min(clearance);
            if crossed_at_x.is_none() && ego.y_m > road.y_lane_m() {
                crossed_at_x = Some(ego.x_m);
            }
        }
        let crossed_at_x = crossed_at_x.expect("the ego must cross the divider");
        assert!(
            crossed_at_x < road.merge_end_x_m - 20.0,
            "{kind}: crossed at {crossed_at_x}"
        );
        assert!(
            min_edge_clearance_m > 0.2,
            "{kind}: clearance {min_edge_clearance_m}"
        );
        let upper = road.lane_center_y_m(Lane::Upper);
        assert!(
            (states[0].y_m - upper).abs() < 0.3,
            "{kind}: ended at y = {}",
            states[0].y_m
        );
        println!(
            "{kind}: ego crossed the divider at x = {crossed_at_x:.1} m, min clearance to the \
             lower edge {min_edge_clearance_m:.2} m, final y {:.2} m",
            states[0].y_m
        );
    }
}

/// PF-SP, the paper's risk-aware baseline without V2V: it slows for a slower vehicle ahead in
/// its lane (60 m ahead at 10 m/s, predicted along its lane), keeps its target speed when
/// alone, and its risk term never pushes it above the target (a faster vehicle closing from
/// behind does not make it speed up). (Much closer, the prediction would run the ego through
/// the leader within the horizon, where a bounded field rewards passing through: README,
/// "Limits".)
#[test]
fn pf_sp_brakes_for_risk_ahead_and_never_races() {
    let road = MergeRoad {
        merge_start_x_m: 0.0,
        merge_end_x_m: 50.0,
        start_x_m: -100.0,
        ..MergeRoad::default()
    };
    let ego = state(100.0, 5.25, 0.0, 15.0);
    let plan = |neighbours: &[Neighbour]| {
        PfPlanner::new(
            PlannerKind::PfSp,
            PlannerParams::default(),
            road.lane_road().unwrap(),
        )
        .unwrap()
        .plan(&request(ego, 15.0, neighbours, &[]))
        .unwrap()
    };
    let first_speed = |p: &Plan| p.path[1].speed_mps;
    let alone = plan(&[]);
    assert!(
        (first_speed(&alone) - 15.0).abs() < 0.1,
        "{}",
        first_speed(&alone)
    );
    let slow_ahead = [Neighbour {
        id: 1,
        state: state(160.0, 5.25, 0.0, 10.0),
        shape: VehicleShape::default(),
    }];
    let braking = plan(&slow_ahead);
    assert!(
        first_speed(&braking) < 14.5,
        "{:?} {:?}",
        braking.path.iter().map(|p| p.speed_mps).collect::<Vec<_>>(),
        braking
            .path
            .iter()
            .map(|p| (p.x_m, p.y_m))
            .collect::<Vec<_>>()
    );
    // PF-SP-EQ10 (no risk term) would not brake.
    let eq10 = PfPlanner::new(
        PlannerKind::PfSpEq10,
        PlannerParams::default(),
        road.lane_road().unwrap(),
    )
    .unwrap()
    .plan(&request(ego, 15.0, &slow_ahead, &[]))
    .unwrap();
    assert!(first_speed(&eq10) > 14.9);
    let fast_behind = [Neighbour {
        id: 1,
        state: state(85.0, 5.25, 0.0, 22.0),
        shape: VehicleShape::default(),
    }];
    let chased = plan(&fast_behind);
    assert!(
        chased.path.iter().all(|p| p.speed_mps <= 15.0 + 1e-6),
        "{:?}",
        chased.path.iter().map(|p| p.speed_mps).collect::<Vec<_>>()
    );
}
