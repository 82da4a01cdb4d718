use planner::*;
#[test]
fn debug() {
    let road = MergeRoad::default();
    let params = PlannerParams::default();
    let mut p = PfPlanner::new(PlannerKind::PfCs, params.clone(), road.clone()).unwrap();
    let shape = VehicleShape::default();
    let ego = VehicleState { x_m: 220.0, y_m: 3.49, yaw_rad: 0.04, speed_mps: 20.0 };
    let obs = VehicleState { x_m: 225.0, y_m: 5.79, yaw_rad: 0.0, speed_mps: 15.0 };
    let nb = [Neighbour { id: 1, state: obs, shape }];
    let req = PlanRequest { time_s: 0.0, ego_id: 0, ego, ego_shape: shape, target_speed_mps: 20.0, mu: 0.8, neighbours: &nb, shared_paths: &[] };
    let plan = p.plan(&req).unwrap();
    let f = p.field(&req);
    for (w, q) in plan.waypoints.iter().zip(&plan.path[1..]) {
        let fo = f.obstacles[0].gradient(w[0], w[1]);
        let fr = f.road.gradient(w[0], w[1]);
        println!("wp ({:7.2},{:5.2}) cubic ({:7.2},{:5.2})  obs grad ({:+.3},{:+.3}) road grad ({:+.3},{:+.3})", w[0], w[1], q.x_m, q.y_m, fo[0], fo[1], fr[0], fr[1]);
    }
    println!("{:?} sigmas {:?}", plan.cubic, f.obstacles[0]);
}
