use planner::*;

fn advance(plan: &Plan, t: f64, v0: f64) -> VehicleState {
    let path = &plan.path;
    let k = path.partition_point(|p| p.t_s <= t).clamp(1, path.len() - 1);
    let a = path[k - 1];
    let b = path[k];
    let f = ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.5);
    let x = a.x_m + f * (b.x_m - a.x_m);
    let y = a.y_m + f * (b.y_m - a.y_m);
    let speed = if k == 1 { v0 + f * (a.speed_mps - v0) } else { a.speed_mps };
    VehicleState { x_m: x, y_m: y, yaw_rad: (b.y_m - a.y_m).atan2(b.x_m - a.x_m), speed_mps: speed }
}

#[test]
fn explore() {
    let x0: f64 = std::env::var("X0").ok().and_then(|v| v.parse().ok()).unwrap_or(25.0);
    let verbose = std::env::var("VERB").is_ok();
    for kind in PlannerKind::ALL {
        let road = MergeRoad::default();
        let mut params = PlannerParams::default();
        if let Ok(v) = std::env::var("PRED") { params.predict_obstacles_in_path = v == "1"; }
        if let Ok(v) = std::env::var("FLOOR") { params.interaction_floor = v.parse().unwrap(); }
        if let Ok(v) = std::env::var("TAU") { params.obstacle_time_gap_s = v.parse().unwrap(); }
        if let Ok(v) = std::env::var("W3") { params.interaction_weight = v.parse().unwrap(); }
        let mut planners = [PfPlanner::new(kind, params.clone(), road.clone()).unwrap(), PfPlanner::new(kind, params.clone(), road.clone()).unwrap()];
        let mut states = [
            VehicleState { x_m: 0.0, y_m: 1.75, yaw_rad: 0.0, speed_mps: 20.0 },
            VehicleState { x_m: x0, y_m: 5.25, yaw_rad: 0.0, speed_mps: 15.0 },
        ];
        let targets = [20.0, 15.0];
        let shape = VehicleShape::default();
        let mut shared: Vec<SharedLocalPath> = Vec::new();
        let dt = 0.1;
        println!("=== {kind}");
        let mut total_solves = 0;
        let mut min_gap = f64::INFINITY; let mut min_gap_t = 0.0;
        let mut obs_min_v = (f64::INFINITY, 0.0); let mut obs_max_dy: f64 = 0.0; let mut obs_dy_x = 0.0;
        let mut merge_x = f64::NAN; let mut max_yaw: [f64;2] = [0.0, 0.0];
        let mut obs_yaw_changes = 0; let mut last_sign = 0.0;
        let mut fallbacks = 0;
        for step in 0..250 {
            let t = step as f64 * dt;
            let mut plans = Vec::new();
            for i in 0..2 {
                let neighbours: Vec<Neighbour> = (0..2).filter(|j| *j != i).map(|j| Neighbour { id: j as u32, state: states[j], shape }).collect();
                let req = PlanRequest { time_s: t, ego_id: i as u32, ego: states[i], ego_shape: shape, target_speed_mps: targets[i], mu: 0.8, neighbours: &neighbours, shared_paths: &shared };
                let plan = planners[i].plan(&req).unwrap();
                total_solves += planners[i].last_stats().speed_solves;
                if plan.fallback.is_some() { fallbacks += 1; println!("fallback {:?}", plan.fallback); }
                plans.push(plan);
            }
            shared = plans.iter().map(|p| p.shared.clone()).collect();
            let d = ((states[0].x_m - states[1].x_m).powi(2) + (states[0].y_m - states[1].y_m).powi(2)).sqrt();
            if d < min_gap { min_gap = d; min_gap_t = t; }
            if states[1].speed_mps < obs_min_v.0 { obs_min_v = (states[1].speed_mps, t); }
            if (states[1].y_m - 5.25).abs() > obs_max_dy { obs_max_dy = (states[1].y_m - 5.25).abs(); obs_dy_x = states[1].x_m; }
            if merge_x.is_nan() && states[0].y_m > 3.5 { merge_x = states[0].x_m; }
            for i in 0..2 { max_yaw[i] = max_yaw[i].max(states[i].yaw_rad.abs()); }
            if states[1].yaw_rad.abs() > 0.005 { let s = states[1].yaw_rad.signum(); if s != last_sign { obs_yaw_changes += 1; last_sign = s; } }
            if verbose && step % std::env::var("EVERY").ok().and_then(|v| v.parse().ok()).unwrap_or(5) == 0 {
                println!("t={t:5.1} ego ({:6.1},{:5.2}) v={:5.2} | obs ({:6.1},{:5.2}) v={:5.2}  edge={:.2} v1..: {:.1} {:.1} {:.1}",
                    states[0].x_m, states[0].y_m, states[0].speed_mps, states[1].x_m, states[1].y_m, states[1].speed_mps,
                    road.lower_edge_y_m(states[0].x_m), plans[1].path[1].speed_mps, plans[1].path[10].speed_mps, plans[1].path[20].speed_mps);
            }
            for i in 0..2 { states[i] = advance(&plans[i], t + dt, states[i].speed_mps); }
        }
        println!("solves {total_solves} fallbacks {fallbacks} min centre dist {min_gap:.2} at {min_gap_t:.1}s, obs min v {:.2} at {:.1}s, obs max |dy| {obs_max_dy:.2} at x {obs_dy_x:.0}, ego merge x {merge_x:.1}, max yaw ego {:.3} obs {:.3}, obs yaw sign changes {obs_yaw_changes}", obs_min_v.0, obs_min_v.1, max_yaw[0], max_yaw[1]);
    }
}
