//! A fixed planning workload for instruction counts and paired timings: the encounter of the
//! `plan_cycle` bench's `pf_iso_plan_cycle_n20_one_neighbour_moving` (PF-ISO ego at x = 150 m in
//! the ending lane at 20 m/s, a PF-ISO neighbour 10 m ahead in the through lane at 15 m/s with
//! its shared path, 40 cycles 0.1 s apart, warm-started as in the closed loop), replayed
//! `ROUNDS` times (default 50) with a fresh planner per round. Prints the cycles run and the
//! wall time per cycle.
//!
//! `cargo run --release -p planner --example plan_cycle_workload -- 50`
//! (under `perf stat -e instructions:u` the count does not depend on the machine's load).

use std::time::Instant;

use mergesim_types::{MergeRoad, Neighbour, VehicleShape, VehicleState};
use planner::params::PlannerParams;
use planner::{PfPlanner, PlanRequest, PlannerKind};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rounds: usize = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 50,
    };
    let lanes = std::sync::Arc::new(MergeRoad::default().lane_road()?);
    let params = PlannerParams::default();
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
    let (period_s, cycles) = (0.1, 40);
    let mut other_planner = PfPlanner::new(PlannerKind::PfIso, params.clone(), lanes.clone())?;
    let mut moving = Vec::with_capacity(cycles);
    for k in 0..cycles {
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
            })?
            .shared;
        moving.push((t_s, ego_k, other_k, vec![shared]));
    }
    let prepared = PfPlanner::new(PlannerKind::PfIso, params.clone(), lanes)?;
    let start = Instant::now();
    let mut checksum = 0.0;
    for _ in 0..rounds {
        let mut planner = PfPlanner::on_geometry(
            PlannerKind::PfIso,
            params.clone(),
            prepared.road_geometry().clone(),
        )?;
        for (t_s, ego_k, other_k, shared) in &moving {
            let neighbours = [Neighbour {
                id: 1,
                state: *other_k,
                shape,
            }];
            let plan = planner.plan(&PlanRequest {
                time_s: *t_s,
                ego_id: 0,
                ego: *ego_k,
                ego_shape: shape,
                target_speed_mps: 20.0,
                mu: 0.8,
                neighbours: &neighbours,
                shared_paths: shared,
            })?;
            checksum += plan.path.last().map_or(0.0, |p| p.x_m);
        }
    }
    let per_cycle_us = start.elapsed().as_secs_f64() * 1e6 / (rounds * cycles) as f64;
    println!(
        "{} cycles, {per_cycle_us:.1} µs per cycle (checksum {checksum:.6})",
        rounds * cycles
    );
    Ok(())
}
