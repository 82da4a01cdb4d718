//! The planners on roads of lanes: the universal field in the lane frame (finite differences,
//! a rotated copy of a road), the lane-end rule, and a closed loop on the curved merge.

use std::sync::Arc;

use mergesim_types::lanes::{
    ENDING_LANE_ID, LaneRoad, LaneRoadSpec, THROUGH_LANE_ID, curved_merge_spec,
};
use mergesim_types::{MergeRoad, Neighbour, SharedLocalPath, VehicleShape, VehicleState};
use planner::lane_road_field::LaneRoadGeometry;
use planner::obstacle_field::HeadingForm;
use planner::params::PlannerParams;
use planner::potential_field::PotentialField;
use planner::potential_field::UniversalFieldParams;
use planner::{ParameterSet, PfPlanner, PlanRequest, PlannerKind};

fn state(x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> VehicleState {
    VehicleState {
        x_m,
        y_m,
        yaw_rad,
        speed_mps,
    }
}

fn curved_spec() -> LaneRoadSpec {
    curved_merge_spec(&MergeRoad::default(), 300.0).unwrap()
}

fn index_of(road: &LaneRoad, id: mergesim_types::lanes::LaneId) -> usize {
    road.lanes().iter().position(|l| l.id() == id).unwrap()
}

/// A vehicle on `lane` at (s, d), heading along the lane plus `yaw_offset_rad`.
fn on_lane(
    road: &LaneRoad,
    lane: usize,
    s_m: f64,
    d_m: f64,
    yaw_offset_rad: f64,
    v: f64,
) -> VehicleState {
    let l = &road.lanes()[lane];
    let p = l.point(s_m, d_m);
    state(p[0], p[1], l.heading_rad(s_m) + yaw_offset_rad, v)
}

fn neighbour(id: u32, s: VehicleState) -> Neighbour {
    Neighbour {
        id,
        state: s,
        shape: VehicleShape::default(),
    }
}

/// The universal field (road terms with the lane-end walls, the target lane's pull, two
/// obstacles) on the 300 m curved merge: its gradient matches central differences of its value.
#[test]
fn universal_field_gradient_matches_finite_differences_on_the_curved_merge() {
    let road = LaneRoad::new(&curved_spec()).unwrap();
    let geometry = LaneRoadGeometry::new(&road);
    let (through, ending) = (
        index_of(&road, THROUGH_LANE_ID),
        index_of(&road, ENDING_LANE_ID),
    );
    for form in [HeadingForm::Rotation, HeadingForm::PaperCorrelation] {
        let params = PlannerParams {
            obstacle_heading_form: form,
            ..PlannerParams::default()
        };
        // An ego in the through lane (walls on) and one in the ending lane (target: through).
        for ego in [
            on_lane(&road, through, 120.0, 0.0, 0.0, 20.0),
            on_lane(&road, ending, 120.0, 0.0, 0.0, 20.0),
        ] {
            let others = [
                neighbour(1, on_lane(&road, through, 150.0, 0.3, 0.04, 15.0)),
                neighbour(2, on_lane(&road, ending, 100.0, -0.2, -0.03, 22.0)),
            ];
            let field = PotentialField::new(
                &UniversalFieldParams::from(&params),
                &geometry,
                0,
                &ego,
                &VehicleShape::default(),
                &others,
            );
            assert_eq!(field.target_lane, through);
            let mut worst = 0.0_f64;
            for i in 0..400 {
                // Off the obstacles' s and the edge clamp's d: the field is C¹ only there (Eq. 3's
                // linear continuation, Eq. 4's two halves), where a central difference straddling
                // the join is not the derivative.
                let s = 60.0137 + 0.5 * i as f64;
                let d = -5.0123 + 10.5 * ((i * 37) % 100) as f64 / 100.0;
                let p = road.lanes()[ending].point(s, d);
                let g = field.gradient(p[0], p[1]);
                let h = 1e-5;
                let fx = (field.value(p[0] + h, p[1]) - field.value(p[0] - h, p[1])) / (2.0 * h);
                let fy = (field.value(p[0], p[1] + h) - field.value(p[0], p[1] - h)) / (2.0 * h);
                let scale = 1.0 + fx.abs().max(fy.abs());
                let err = ((g[0] - fx).abs().max((g[1] - fy).abs())) / scale;
                worst = worst.max(err);
            }
            assert!(worst < 1e-6, "{form:?}: worst relative error {worst}");
        }
    }
}

fn rotate_shift(p: [f64; 2], angle: f64, shift: [f64; 2]) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [
        c * p[0] - s * p[1] + shift[0],
        s * p[0] + c * p[1] + shift[1],
    ]
}

/// The same universal field on a rotated and shifted copy of the curved merge: obstacles
/// heading along their lanes (and 0.05 rad off) give the same values, and gradients rotated
/// with the map, with either reading of Eq. 4's heading terms.
#[test]
fn a_rotated_copy_of_the_road_gives_the_same_field() {
    let spec = curved_spec();
    let (angle, shift) = (2.2, [1234.5, -987.6]);
    let moved = LaneRoadSpec {
        lanes: spec
            .lanes
            .iter()
            .map(|l| {
                let mut l = l.clone();
                l.centreline_m = l
                    .centreline_m
                    .iter()
                    .map(|&p| rotate_shift(p, angle, shift))
                    .collect();
                l
            })
            .collect(),
        tolerances: spec.tolerances.clone(),
    };
    let (a, b) = (
        LaneRoad::new(&spec).unwrap(),
        LaneRoad::new(&moved).unwrap(),
    );
    let (ga, gb) = (LaneRoadGeometry::new(&a), LaneRoadGeometry::new(&b));
    let (through, ending) = (index_of(&a, THROUGH_LANE_ID), index_of(&a, ENDING_LANE_ID));
    let rotate_state = |s: VehicleState| {
        let p = rotate_shift([s.x_m, s.y_m], angle, shift);
        state(p[0], p[1], s.yaw_rad + angle, s.speed_mps)
    };
    for form in [HeadingForm::Rotation, HeadingForm::PaperCorrelation] {
        let params = PlannerParams {
            obstacle_heading_form: form,
            ..PlannerParams::default()
        };
        let ego = on_lane(&a, through, 100.0, 0.1, 0.0, 20.0);
        let others = [
            neighbour(1, on_lane(&a, through, 140.0, 0.0, 0.05, 15.0)),
            neighbour(2, on_lane(&a, ending, 110.0, 0.0, 0.0, 22.0)),
        ];
        let others_b: Vec<Neighbour> = others
            .iter()
            .map(|n| neighbour(n.id, rotate_state(n.state)))
            .collect();
        let fa = PotentialField::new(
            &UniversalFieldParams::from(&params),
            &ga,
            0,
            &ego,
            &VehicleShape::default(),
            &others,
        );
        let fb = PotentialField::new(
            &UniversalFieldParams::from(&params),
            &gb,
            0,
            &rotate_state(ego),
            &VehicleShape::default(),
            &others_b,
        );
        assert_eq!(
            fa.road.walls.len(),
            1,
            "the ego in the through lane sees the wall"
        );
        assert_eq!(fa.road.walls.len(), fb.road.walls.len());
        let (sin, cos) = angle.sin_cos();
        let mut worst = 0.0_f64;
        for i in 0..300 {
            let s = 80.0 + 0.4 * i as f64;
            let d = -4.0 + 8.0 * ((i * 29) % 100) as f64 / 100.0;
            let p = a.lanes()[ending].point(s, d);
            let q = rotate_shift(p, angle, shift);
            let (va, vb) = (fa.value(p[0], p[1]), fb.value(q[0], q[1]));
            let (g, h) = (fa.gradient(p[0], p[1]), fb.gradient(q[0], q[1]));
            let g_rot = [cos * g[0] - sin * g[1], sin * g[0] + cos * g[1]];
            let scale = 1.0 + va.abs() + g[0].abs() + g[1].abs();
            worst = worst
                .max((va - vb).abs() / scale)
                .max((g_rot[0] - h[0]).abs() / scale)
                .max((g_rot[1] - h[1]).abs() / scale);
        }
        assert!(worst < 1e-8, "{form:?}: worst relative difference {worst}");
    }
}

/// The lane-end rule: a lane that ends is never a target, and a vehicle in the through lane
/// beside it does not pass a slower car ahead through the ending lane, on the straight merge
/// road and on the curved one.
#[test]
fn a_lane_that_ends_is_never_a_target_and_the_through_lane_does_not_swerve_into_it() {
    for spec in [MergeRoad::default().lane_road_spec(), curved_spec()] {
        let road = Arc::new(LaneRoad::new(&spec).unwrap());
        let geometry = LaneRoadGeometry::shared(road.clone());
        let (through, ending) = (
            index_of(&road, THROUGH_LANE_ID),
            index_of(&road, ENDING_LANE_ID),
        );
        assert!(geometry.lane_ends(ending) && !geometry.lane_ends(through));
        assert_eq!(geometry.target_lane(ending), through);
        assert_eq!(geometry.target_lane(through), through);
        for kind in PlannerKind::ALL {
            // A van in the through lane at 25 m/s closing on a car at 12 m/s 30 m ahead.
            let mut van_planner =
                PfPlanner::new(kind, PlannerParams::default(), road.clone()).unwrap();
            let mut van = on_lane(&road, through, 20.0, 0.0, 0.0, 25.0);
            let mut slow = on_lane(&road, through, 50.0, 0.0, 0.0, 12.0);
            let end_s = road.lanes()[ending].length_m();
            let mut lowest_d = f64::INFINITY;
            for step in 0..80 {
                let t_s = 0.1 * step as f64;
                let neighbours = [neighbour(1, slow)];
                let plan = van_planner
                    .plan(&PlanRequest {
                        time_s: t_s,
                        ego_id: 0,
                        ego: van,
                        ego_shape: VehicleShape::default(),
                        target_speed_mps: 25.0,
                        mu: 0.8,
                        neighbours: &neighbours,
                        shared_paths: &[],
                    })
                    .unwrap();
                // Every planned point beside the ending lane stays on the through lane's side
                // of the divider (its centre at least half a car's width from it).
                for p in &plan.path {
                    let fp = road.lanes()[through].project([p.x_m, p.y_m]);
                    let beside = road.lanes()[ending].project([p.x_m, p.y_m]).s_m < end_s;
                    if beside {
                        lowest_d = lowest_d.min(fp.d_m);
                    }
                }
                van = plan.kinematic_state_at(&van, t_s + 0.1);
                let ahead = road.lanes()[through].project([slow.x_m, slow.y_m]).s_m + 1.2;
                slow = on_lane(&road, through, ahead, 0.0, 0.0, 12.0);
            }
            // The divider is at d = −1.75 in the through lane's frame.
            assert!(
                lowest_d > -1.75 + 0.5 * VehicleShape::default().width_m,
                "{kind}: the van's path reached d = {lowest_d:.2} m"
            );
        }
    }
}

/// The paper's urgent merge on the 300 m-radius curved road, rolled forward kinematically
/// along the vehicles' own plans (replanning every 0.1 s, V2V ideal): the ego leaves the
/// ending lane well before it ends, never comes within 0.2 m of the drivable area's outer
/// edges, and settles on the through lane's centre; the other car stays in the through lane.
#[test]
fn every_planner_merges_on_the_curved_road_and_stays_in_lane() {
    let road = Arc::new(LaneRoad::new(&curved_spec()).unwrap());
    let (through, ending) = (
        index_of(&road, THROUGH_LANE_ID),
        index_of(&road, ENDING_LANE_ID),
    );
    let shape = VehicleShape::default();
    let half_width_m = 0.5 * shape.width_m;
    let end_s = road.lanes()[ending].length_m();
    for kind in PlannerKind::ALL {
        let mut planners = [
            PfPlanner::new(kind, PlannerParams::default(), road.clone()).unwrap(),
            PfPlanner::new(kind, PlannerParams::default(), road.clone()).unwrap(),
        ];
        let mut states = [
            on_lane(&road, ending, 50.0, 0.0, 0.0, 20.0),
            on_lane(&road, through, 75.0, 0.0, 0.0, 15.0),
        ];
        let targets = [20.0, 15.0];
        let mut shared: Vec<SharedLocalPath> = Vec::new();
        let mut merged_at_s = None;
        let mut min_clearance_m = f64::INFINITY;
        let mut other_lowest_d = f64::INFINITY;
        for step in 0..200 {
            let t_s = 0.1 * step as f64;
            let mut plans = Vec::new();
            for i in 0..2 {
                let neighbours = [Neighbour {
                    id: (1 - i) as u32,
                    state: states[1 - i],
                    shape,
                }];
                let plan = planners[i]
                    .plan(&PlanRequest {
                        time_s: t_s,
                        ego_id: i as u32,
                        ego: states[i],
                        ego_shape: shape,
                        target_speed_mps: targets[i],
                        mu: 0.8,
                        neighbours: &neighbours,
                        shared_paths: &shared,
                    })
                    .unwrap();
                assert!(plan.fallback.is_none(), "{kind}: fallback at {t_s}");
                plans.push(plan);
            }
            shared = plans.iter().map(|p| p.shared.clone()).collect();
            for i in 0..2 {
                states[i] = plans[i].kinematic_state_at(&states[i], t_s + 0.1);
                let p = [states[i].x_m, states[i].y_m];
                min_clearance_m =
                    min_clearance_m.min(road.signed_distance_to_edge_m(p) - half_width_m);
            }
            let ego = [states[0].x_m, states[0].y_m];
            let in_through = road.lanes()[through].project(ego);
            // Merged: the whole body across the divider (d = −1.75 in the through lane).
            if merged_at_s.is_none() && in_through.d_m - half_width_m > -1.75 {
                merged_at_s = Some(road.lanes()[ending].project(ego).s_m);
            }
            let other = road.lanes()[through].project([states[1].x_m, states[1].y_m]);
            other_lowest_d = other_lowest_d.min(other.d_m);
        }
        let merged_at_s = merged_at_s.expect("the ego must merge");
        assert!(
            merged_at_s < end_s - 20.0,
            "{kind}: merged at s = {merged_at_s:.1} m of {end_s:.1}"
        );
        assert!(
            min_clearance_m > 0.2,
            "{kind}: clearance to the edges {min_clearance_m:.2} m"
        );
        let final_d = road.lanes()[through]
            .project([states[0].x_m, states[0].y_m])
            .d_m;
        // Settled in the through lane, its body well inside it (0.945 m each side for a
        // centred car). Measured 2026-12-02: d = 0.30 m for every planner, towards the inside
        // of the curve; the straight road's test settles within 0.3 m of the centre.
        assert!(final_d.abs() < 0.5, "{kind}: ended at d = {final_d:.2} m");
        assert!(
            other_lowest_d > -1.75 + half_width_m,
            "{kind}: the other car reached d = {other_lowest_d:.2} m"
        );
        println!(
            "{kind}: merged (whole body across the divider) at s = {merged_at_s:.1} m of the \
             {end_s:.1} m ending lane, min clearance to the edges {min_clearance_m:.2} m, \
             final d {final_d:.2} m"
        );
    }
}

/// The lane-end rule's walls are a `mergesim` improvement: a car settled in the through lane
/// beside the ending lane sees the divider as a wall with `lane_end_walls` (the `mergesim` set)
/// and only Eq. 2's soft divider term without (the `paper` set).
#[test]
fn the_lane_end_walls_are_on_in_the_mergesim_set_and_off_in_the_paper_set() {
    let road = Arc::new(LaneRoad::new(&MergeRoad::default().lane_road_spec()).unwrap());
    let through = index_of(&road, THROUGH_LANE_ID);
    let car = on_lane(&road, through, 100.0, 0.0, 0.0, 20.0);
    let walls = |set: ParameterSet| {
        let planner =
            PfPlanner::new(PlannerKind::PfIso, set.planner_params(), road.clone()).unwrap();
        let req = PlanRequest {
            time_s: 0.0,
            ego_id: 0,
            ego: car,
            ego_shape: VehicleShape::default(),
            target_speed_mps: 20.0,
            mu: 0.8,
            neighbours: &[],
            shared_paths: &[],
        };
        planner.field(&req).road.walls.len()
    };
    assert_eq!(walls(ParameterSet::Mergesim), 1);
    assert_eq!(walls(ParameterSet::Paper), 0);
}

/// On the on-ramp road the ramp's left bound is an outer edge whose far side, across the gore,
/// is the main road: a car on the main road is on the road, not beyond that edge. (Before the
/// edge distance was made positive on every drivable point, the ramp's edge pushed a car in
/// the main road's right lane towards the gore until its waypoints stopped advancing at the
/// acceleration lane's start, and every planner fell back from t = 0 on the `on_ramp` built-in.)
#[test]
fn a_car_on_the_main_road_beside_an_on_ramp_keeps_its_lane() {
    use mergesim_types::lanes::{LaneId, OnRampParams, on_ramp_spec};
    let road = Arc::new(LaneRoad::new(&on_ramp_spec(&OnRampParams::default()).unwrap()).unwrap());
    let right_main = index_of(&road, LaneId(2));
    for kind in PlannerKind::ALL {
        let mut planner = PfPlanner::new(kind, PlannerParams::default(), road.clone()).unwrap();
        let car = on_lane(&road, right_main, 120.0, 0.0, 0.0, 15.0);
        let plan = planner
            .plan(&PlanRequest {
                time_s: 0.0,
                ego_id: 0,
                ego: car,
                ego_shape: VehicleShape::default(),
                target_speed_mps: 15.0,
                mu: 0.8,
                neighbours: &[],
                shared_paths: &[],
            })
            .unwrap();
        assert_eq!(plan.fallback, None, "{kind}");
        for p in &plan.path {
            let d = road.lanes()[right_main].project([p.x_m, p.y_m]).d_m;
            assert!(d.abs() < 0.3, "{kind}: planned point {p:?} at d = {d:.2} m");
        }
    }
}
