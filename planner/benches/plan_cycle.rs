//! One full PF-ISO planning cycle (N = 20, one neighbour with a shared local path):
//! field → waypoints → cubic fit → SCP speed optimisation → plan.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mergesim_types::{MergeRoad, Neighbour, SharedLocalPath, VehicleShape, VehicleState};
use planner::params::PlannerParams;
use planner::speed_optimisation::SpeedProgram;
use planner::{PfPlanner, PlanRequest, PlannerKind};

type SharedLocalPathVec = Vec<SharedLocalPath>;

fn plan_cycle(c: &mut Criterion) {
    let road = MergeRoad::default();
    let params = PlannerParams::default();
    assert_eq!(params.waypoint_count, 20);
    let shape = VehicleShape::default();
    let ego = VehicleState {
        x_m: 150.0,
        y_m: 1.75,
        yaw_rad: 0.0,
        speed_mps: 20.0,
    };
    let other = VehicleState {
        x_m: 160.0,
        y_m: 5.25,
        yaw_rad: 0.0,
        speed_mps: 15.0,
    };
    // The neighbour's SLP: its own PF-ISO plan at the same instant.
    let mut other_planner = PfPlanner::new(
        PlannerKind::PfIso,
        params.clone(),
        road.lane_road().expect("valid road"),
    )
    .expect("valid");
    let ego_as_neighbour = [Neighbour {
        id: 0,
        state: ego,
        shape,
    }];
    let other_plan = other_planner
        .plan(&PlanRequest {
            time_s: 8.0,
            ego_id: 1,
            ego: other,
            ego_shape: shape,
            target_speed_mps: 15.0,
            mu: 0.8,
            neighbours: &ego_as_neighbour,
            shared_paths: &[],
        })
        .expect("valid request");
    let shared = [other_plan.shared];
    let neighbours = [Neighbour {
        id: 1,
        state: other,
        shape,
    }];
    let request = PlanRequest {
        time_s: 8.0,
        ego_id: 0,
        ego,
        ego_shape: shape,
        target_speed_mps: 20.0,
        mu: 0.8,
        neighbours: &neighbours,
        shared_paths: &shared,
    };
    let mut planner = PfPlanner::new(
        PlannerKind::PfIso,
        params,
        road.lane_road().expect("valid road"),
    )
    .expect("valid");
    let plan = planner.plan(&request).expect("valid request");
    assert!(plan.fallback.is_none());
    let stats = planner.last_stats();
    eprintln!(
        "PF-ISO cycle: {} speed solves, cubic QP: {}, interacting vehicles: {}",
        stats.speed_solves, stats.cubic_qp, stats.interacting_vehicles
    );
    c.bench_function("pf_iso_plan_cycle_n20_one_neighbour", |b| {
        b.iter(|| planner.plan(black_box(&request)))
    });
    let mut fresh = PfPlanner::new(
        PlannerKind::PfIso,
        planner.params().clone(),
        planner.shared_road(),
    )
    .expect("valid");
    c.bench_function("pf_iso_plan_cycle_cold_solver", |b| {
        b.iter(|| {
            fresh = PfPlanner::new(
                PlannerKind::PfIso,
                planner.params().clone(),
                planner.shared_road(),
            )
            .expect("valid");
            fresh.plan(black_box(&request))
        })
    });
    // The same encounter as it unfolds: both vehicles advance at their speeds, one planning
    // period (0.1 s) per cycle, and the neighbour's shared path is re-planned each time (outside
    // the timing), so every cycle warm-starts from the previous cycle's plan shifted in time as
    // in the closed loop. A static request re-planned at the same instant converges onto its
    // own optimum and flatters any warm start; this one does not.
    let period_s = 0.1;
    let cycles = 40;
    let mut other_planner = PfPlanner::new(
        PlannerKind::PfIso,
        planner.params().clone(),
        planner.shared_road(),
    )
    .expect("valid");
    let moving: Vec<(f64, VehicleState, VehicleState, SharedLocalPathVec)> = (0..cycles)
        .map(|k| {
            let t_s = 8.0 + period_s * k as f64;
            let dt_s = t_s - 8.0;
            let ego_k = VehicleState {
                x_m: ego.x_m + ego.speed_mps * dt_s,
                ..ego
            };
            let other_k = VehicleState {
                x_m: other.x_m + other.speed_mps * dt_s,
                ..other
            };
            let shared = other_planner
                .plan(&PlanRequest {
                    time_s: t_s,
                    ego_id: 1,
                    ego: other_k,
                    ego_shape: shape,
                    target_speed_mps: 15.0,
                    mu: 0.8,
                    neighbours: &[Neighbour {
                        id: 0,
                        state: ego_k,
                        shape,
                    }],
                    shared_paths: &[],
                })
                .expect("valid request")
                .shared;
            (t_s, ego_k, other_k, vec![shared])
        })
        .collect();
    // The defaults (the Newton QP, the SCP iterated to convergence: at most 20 iterations,
    // stalled below a 1 cm/s trust region; docs/parameters.md), the cone program iterated the
    // same way, the defaults without the step-size stop (before 2026-12-03), and the defaults
    // before 2026-12-02 (the cone program, two SCP iterations).
    let with = |program: SpeedProgram,
                max_scp_iterations: usize,
                stall_mps: f64,
                step_tolerance_mps: f64| PlannerParams {
        speed_program: program,
        max_scp_iterations,
        scp_stall_trust_region_mps: stall_mps,
        scp_step_tolerance_mps: step_tolerance_mps,
        ..planner.params().clone()
    };
    for (name, params) in [
        (
            "pf_iso_plan_cycle_n20_one_neighbour_moving",
            planner.params().clone(),
        ),
        (
            "pf_iso_plan_cycle_n20_one_neighbour_moving_cone",
            with(SpeedProgram::Cone, 20, 0.01, 0.01),
        ),
        (
            "pf_iso_plan_cycle_n20_one_neighbour_moving_no_step_stop",
            with(SpeedProgram::NewtonQp, 20, 0.01, 0.0),
        ),
        (
            "pf_iso_plan_cycle_n20_one_neighbour_moving_cone_two_iterations",
            with(SpeedProgram::Cone, 2, 0.0, 0.0),
        ),
    ] {
        // A fresh planner on the road already prepared (as a simulation builds its planners
        // once per run; before the lane frame this cloned the `MergeRoad`).
        let fresh = || {
            PfPlanner::on_geometry(
                PlannerKind::PfIso,
                params.clone(),
                planner.road_geometry().clone(),
            )
            .expect("valid")
        };
        let mut moving_planner = fresh();
        let mut next = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                let (t_s, ego_k, other_k, shared) = &moving[next % cycles];
                if next % cycles == 0 {
                    // Back to the start of the encounter: no plan from the future to
                    // warm-start.
                    moving_planner = fresh();
                }
                next += 1;
                let neighbours = [Neighbour {
                    id: 1,
                    state: *other_k,
                    shape,
                }];
                moving_planner.plan(black_box(&PlanRequest {
                    time_s: *t_s,
                    ego_id: 0,
                    ego: *ego_k,
                    ego_shape: shape,
                    target_speed_mps: 20.0,
                    mu: 0.8,
                    neighbours: &neighbours,
                    shared_paths: shared,
                }))
            })
        });
    }
    let mut sp = PfPlanner::new(
        PlannerKind::PfSp,
        planner.params().clone(),
        planner.shared_road(),
    )
    .expect("valid");
    c.bench_function("pf_sp_plan_cycle_n20", |b| {
        b.iter(|| sp.plan(black_box(&request)))
    });
}

criterion_group!(benches, plan_cycle);
criterion_main!(benches);
