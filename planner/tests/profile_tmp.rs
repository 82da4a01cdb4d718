use planner::*;
use planner::speed_optimisation::*;
use std::time::Instant;
#[test]
fn profile() {
    let road = MergeRoad::default();
    let params = PlannerParams::default();
    let shape = VehicleShape::default();
    let ego = VehicleState { x_m: 150.0, y_m: 1.75, yaw_rad: 0.0, speed_mps: 20.0 };
    let other = VehicleState { x_m: 160.0, y_m: 5.25, yaw_rad: 0.0, speed_mps: 15.0 };
    let nb = [Neighbour { id: 1, state: other, shape }];
    let req = PlanRequest { time_s: 8.0, ego_id: 0, ego, ego_shape: shape, target_speed_mps: 20.0, mu: 0.8, neighbours: &nb, shared_paths: &[] };
    for kind in [PlannerKind::PfCs, PlannerKind::PfSp, PlannerKind::PfIsoPred] {
        let mut p = PfPlanner::new(kind, params.clone(), road.clone()).unwrap();
        p.plan(&req).unwrap();
        let t = Instant::now();
        for _ in 0..2000 { std::hint::black_box(p.plan(&req).unwrap()); }
        println!("{kind}: {:.1} us/cycle solves {}", t.elapsed().as_secs_f64() / 2000.0 * 1e6, p.last_stats().speed_solves);
    }
    // Raw solve timing.
    let ds = vec![5.0; 20]; let vmax = vec![30.0; 20];
    let prob = SpeedProblem { current_speed_mps: 20.0, target_speed_mps: 20.0, segment_lengths_m: &ds, max_speeds_mps: &vmax, initial_guess_mps: None, interaction: None };
    for (name, prm) in [("accel", params.clone()), ("noaccel", PlannerParams { accel_bound_enabled: false, ..params.clone() }), ("tol1e-6", PlannerParams { solver_tolerance: 1e-6, ..params.clone() })] {
        let mut opt = SpeedOptimiser::new();
        opt.solve(&prm, &prob).unwrap();
        let t = Instant::now();
        for _ in 0..2000 { std::hint::black_box(opt.solve(&prm, &prob).unwrap()); }
        println!("solve {name} warm: {:.1} us", t.elapsed().as_secs_f64() / 2000.0 * 1e6);
        let t = Instant::now();
        for _ in 0..500 { let mut o = SpeedOptimiser::new(); std::hint::black_box(o.solve(&prm, &prob).unwrap()); }
        println!("solve {name} cold: {:.1} us", t.elapsed().as_secs_f64() / 500.0 * 1e6);
    }
}
