//! Property test: random (but finite) states never panic, never return an error, and always
//! give a finite plan whose speeds respect the bounds.

use mergesim_types::{MergeRoad, Neighbour, VehicleShape, VehicleState};
use planner::params::PlannerParams;
use planner::{PfPlanner, PlanRequest, PlannerKind};
use proptest::prelude::*;

fn vehicle() -> impl Strategy<Value = VehicleState> {
    (-40.0..650.0f64, -1.0..8.0f64, -0.6..0.6f64, 0.0..35.0f64).prop_map(|(x, y, yaw, v)| {
        VehicleState {
            x_m: x,
            y_m: y,
            yaw_rad: yaw,
            speed_mps: v,
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn random_requests_give_finite_bounded_plans(
        ego in vehicle(),
        others in proptest::collection::vec(vehicle(), 0..3),
        target in 0.0..32.0f64,
        mu in 0.1..1.2f64,
        kind_index in 0usize..4,
        with_shared in any::<bool>(),
    ) {
        let kind = PlannerKind::ALL[kind_index];
        let params = PlannerParams::default();
        let road = MergeRoad::default();
        let shape = VehicleShape::default();
        let neighbours: Vec<Neighbour> = others
            .iter()
            .enumerate()
            .map(|(k, s)| Neighbour { id: k as u32 + 1, state: *s, shape })
            .collect();
        // The others' SLPs: their own PF-SP plans at the same time.
        let mut shared = Vec::new();
        if with_shared {
            for n in &neighbours {
                let mut p = PfPlanner::new(PlannerKind::PfSp, params.clone(), road.lane_road().unwrap()).unwrap();
                let req = PlanRequest {
                    time_s: 1.0, ego_id: n.id, ego: n.state, ego_shape: shape,
                    target_speed_mps: 15.0, mu, neighbours: &[], shared_paths: &[],
                };
                shared.push(p.plan(&req).unwrap().shared);
            }
        }
        let req = PlanRequest {
            time_s: 1.0, ego_id: 0, ego, ego_shape: shape, target_speed_mps: target, mu,
            neighbours: &neighbours, shared_paths: &shared,
        };
        let mut planner = PfPlanner::new(kind, params.clone(), road.lane_road().unwrap()).unwrap();
        for _ in 0..2 {
            let plan = planner.plan(&req).unwrap();
            prop_assert_eq!(plan.path.len(), params.waypoint_count + 1);
            prop_assert_eq!((plan.path[0].x_m, plan.path[0].y_m), (ego.x_m, ego.y_m));
            // The first point carries the vehicle's speed, the others the planned ones.
            prop_assert_eq!(plan.path[0].speed_mps, ego.speed_mps.max(0.0));
            for p in &plan.path {
                prop_assert!(p.x_m.is_finite() && p.y_m.is_finite() && p.t_s.is_finite());
            }
            for p in &plan.path[1..] {
                prop_assert!(p.speed_mps >= 0.0 && p.speed_mps <= params.speed_limit_mps + 1e-9,
                    "speed {} out of bounds", p.speed_mps);
                // Below v_min only under the stop-and-go cap (down to 0).
                if plan.fallback.is_none() && !planner.last_stats().stop_and_go {
                    prop_assert!(p.speed_mps >= params.min_speed_mps - 1e-9);
                }
            }
            prop_assert!(plan.path.windows(2).all(|w| w[1].t_s >= w[0].t_s));
            prop_assert!(plan.shared.waypoints.iter().all(|w| w.t_s.is_finite()));
        }
    }
}
