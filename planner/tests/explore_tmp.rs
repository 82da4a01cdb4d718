use planner::*;
fn st(x: f64, y: f64, yaw: f64, v: f64) -> VehicleState {
    VehicleState {
        x_m: x,
        y_m: y,
        yaw_rad: yaw,
        speed_mps: v,
    }
}
fn advance(plan: &Plan, now: &VehicleState, t_s: f64) -> VehicleState {
    let path = &plan.path;
    let k = path
        .partition_point(|p| p.t_s <= t_s)
        .clamp(1, path.len() - 1);
    let (a, b) = (path[k - 1], path[k]);
    let f = ((t_s - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
    let v = if k == 1 {
        now.speed_mps + f * (a.speed_mps - now.speed_mps)
    } else {
        a.speed_mps
    };
    st(
        a.x_m + f * (b.x_m - a.x_m),
        a.y_m + f * (b.y_m - a.y_m),
        (b.y_m - a.y_m).atan2(b.x_m - a.x_m),
        v,
    )
}
#[test]
fn explore() {
    let iters: usize = std::env::var("IT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2);
    for x0 in [25.0, 45.0, 55.0, 60.0, 65.0, 80.0] {
        for kind in [
            PlannerKind::PfSp,
            PlannerKind::PfIso,
            PlannerKind::PfIsoPred,
        ] {
            let params = PlannerParams {
                max_scp_iterations: iters,
                ..PlannerParams::default()
            };
            let mk = || PfPlanner::new(kind, params.clone(), MergeRoad::default()).unwrap();
            let mut planners = [mk(), mk()];
            let mut states = [st(0.0, 1.75, 0.0, 20.0), st(x0, 5.25, 0.0, 15.0)];
            let shape = VehicleShape::default();
            let mut shared: Vec<SharedLocalPath> = Vec::new();
            let (mut min_d, mut min_v, mut osc, mut solves, mut max_v) =
                (f64::INFINITY, f64::INFINITY, 0.0, 0, 0.0f64);
            let mut prev_v = [20.0, 15.0];
            let mut min_v_t = 0.0;
            for step in 0..250 {
                let t = 0.1 * step as f64;
                let mut plans = Vec::new();
                for i in 0..2 {
                    let nb = [Neighbour {
                        id: (1 - i) as u32,
                        state: states[1 - i],
                        shape,
                    }];
                    let req = PlanRequest {
                        time_s: t,
                        ego_id: i as u32,
                        ego: states[i],
                        ego_shape: shape,
                        target_speed_mps: [20.0, 15.0][i],
                        mu: 0.8,
                        neighbours: &nb,
                        shared_paths: &shared,
                    };
                    plans.push(planners[i].plan(&req).unwrap());
                    solves += planners[i].last_stats().speed_solves;
                }
                shared = plans.iter().map(|p| p.shared.clone()).collect();
                for i in 0..2 {
                    states[i] = advance(&plans[i], &states[i], t + 0.1);
                }
                // box overlap proxy: |dx| < length and |dy| < width
                let dx = (states[0].x_m - states[1].x_m).abs();
                let dy = (states[0].y_m - states[1].y_m).abs();
                let d = (dx - 4.508).max(dy - 1.61);
                if d < min_d {
                    min_d = d;
                }
                if states[1].speed_mps < min_v {
                    min_v = states[1].speed_mps;
                    min_v_t = t;
                }
                max_v = max_v.max(states[1].speed_mps);
                for i in 0..2 {
                    osc += (states[i].speed_mps - prev_v[i]).abs();
                    prev_v[i] = states[i].speed_mps;
                }
                if std::env::var("X0").ok().and_then(|v| v.parse::<f64>().ok()) == Some(x0)
                    && kind == PlannerKind::PfIso
                    && step >= 100
                    && step < 140
                {
                    println!(
                        "t {t:4.1} ego x {:6.1} y {:4.2} v {:5.2} | obs x {:6.1} v {:5.2} | ego plan v {:?}",
                        states[0].x_m,
                        states[0].y_m,
                        states[0].speed_mps,
                        states[1].x_m,
                        states[1].speed_mps,
                        plans[0]
                            .path
                            .iter()
                            .step_by(4)
                            .map(|p| (p.speed_mps * 10.0).round() / 10.0)
                            .collect::<Vec<_>>()
                    );
                }
            }
            println!(
                "x0 {x0} {kind:12} min box gap proxy {min_d:6.2} obs v min {min_v:5.2} at {min_v_t:4.1} max {max_v:5.2} total |dv| {osc:6.1} solves/plan {:.2}",
                solves as f64 / 500.0
            );
        }
    }
}
