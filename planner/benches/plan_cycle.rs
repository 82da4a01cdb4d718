//! One full PF-ISO planning cycle (N = 20, one neighbour with a shared local path):
//! field → waypoints → cubic fit → SCP speed optimisation → plan.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use planner::{
    MergeRoad, Neighbour, PfPlanner, PlanRequest, PlannerKind, PlannerParams, VehicleShape,
    VehicleState,
};

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
    let mut other_planner =
        PfPlanner::new(PlannerKind::PfIso, params.clone(), road.clone()).expect("valid");
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
    let mut planner = PfPlanner::new(PlannerKind::PfIso, params, road).expect("valid");
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
        planner.road().clone(),
    )
    .expect("valid");
    c.bench_function("pf_iso_plan_cycle_cold_solver", |b| {
        b.iter(|| {
            fresh = PfPlanner::new(
                PlannerKind::PfIso,
                planner.params().clone(),
                planner.road().clone(),
            )
            .expect("valid");
            fresh.plan(black_box(&request))
        })
    });
    let mut sp = PfPlanner::new(
        PlannerKind::PfSp,
        planner.params().clone(),
        planner.road().clone(),
    )
    .expect("valid");
    c.bench_function("pf_sp_plan_cycle_n20", |b| {
        b.iter(|| sp.plan(black_box(&request)))
    });
}

criterion_group!(benches, plan_cycle);
criterion_main!(benches);
