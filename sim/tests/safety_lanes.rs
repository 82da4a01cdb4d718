//! Road-edge checks on roads of lanes: the curved merge road, and a copy of it kilometres
//! from the origin.

use std::sync::Arc;

use mergesim_types::MergeRoad;
use mergesim_types::lanes::{LaneRoad, LaneRoadSpec, THROUGH_LANE_ID, curved_merge_spec};
use sim::safety::{BodyState, EdgeContactEvent, RoadEdge, SafetyMonitor, SafetyParams};

const RADIUS_M: f64 = 300.0;

fn curved_spec(by_m: [f64; 2]) -> LaneRoadSpec {
    let mut spec =
        curved_merge_spec(&MergeRoad::default(), RADIUS_M).unwrap_or_else(|e| panic!("{e}"));
    for lane in &mut spec.lanes {
        for p in &mut lane.centreline_m {
            p[0] += by_m[0];
            p[1] += by_m[1];
        }
    }
    spec
}

fn lanes(by_m: [f64; 2]) -> Arc<LaneRoad> {
    Arc::new(LaneRoad::new(&curved_spec(by_m)).unwrap_or_else(|e| panic!("{e}")))
}

fn body(id: u32, p: [f64; 2], yaw_rad: f64, speed_mps: f64) -> BodyState {
    BodyState {
        id,
        x_m: p[0],
        y_m: p[1],
        yaw_rad,
        vx_mps: speed_mps * yaw_rad.cos(),
        vy_mps: speed_mps * yaw_rad.sin(),
        yaw_rate_radps: 0.0,
        length_m: 4.5,
        width_m: 1.8,
        height_m: 1.4,
    }
}

/// Two cars from s = 30 m of the through lane at 15 m/s for 12 s, checked every 0.05 s: car 0
/// follows the lane's centreline round the left curve, car 1 goes straight on along the
/// tangent (leaving the curve to the right, towards the outer edge). Returns every edge
/// contact event.
fn drive(road: &Arc<LaneRoad>) -> Vec<EdgeContactEvent> {
    let mut monitor =
        SafetyMonitor::new(SafetyParams::default(), road.clone()).unwrap_or_else(|e| panic!("{e}"));
    let lane = road
        .lane(THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let (s0, v, dt) = (30.0, 15.0, 0.05);
    let start = lane.point(s0, 0.0);
    let yaw0 = lane.heading_rad(s0);
    for i in 0..240 {
        let t = f64::from(i) * dt;
        let s = s0 + v * t;
        let in_lane = body(0, lane.point(s, 0.0), lane.heading_rad(s), v);
        let straight = [start[0] + v * t * yaw0.cos(), start[1] + v * t * yaw0.sin()];
        let straight_on = body(1, straight, yaw0, v);
        monitor
            .check(t, &[in_lane, straight_on], dt)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    monitor.edge_contact_events().to_vec()
}

/// On the curve, the car going straight on touches the outer (right-hand, lower) edge once,
/// about when its corner reaches it; the car in its lane touches nothing.
#[test]
fn going_straight_on_in_a_curve_touches_its_outer_edge() {
    let events = drive(&lanes([0.0, 0.0]));
    assert_eq!(events.len(), 1, "{events:?}");
    assert_eq!(events[0].id, 1);
    assert_eq!(events[0].edge, RoadEdge::Lower);
    // The tangent leaves the lane centre by s²/(2R): the through lane's centre is 1.75 m from
    // the outer edge beyond the taper (and farther over the ending lane before it), the car's
    // corner ~0.9 m from its centre line, so contact comes after ~20 m, before 100 m.
    let travelled_m = 15.0 * events[0].t_s;
    assert!(
        (15.0..100.0).contains(&travelled_m),
        "contact after {travelled_m} m"
    );
}

/// The same road and drive 5.9 km from the origin give the same events at the same instants
/// (the checks run on coordinates relative to each body).
#[test]
fn a_far_copy_of_the_curve_gives_the_same_edge_contacts() {
    let by = [5900.0, -3000.0];
    let near = drive(&lanes([0.0, 0.0]));
    let road = lanes(by);
    let mut monitor =
        SafetyMonitor::new(SafetyParams::default(), road.clone()).unwrap_or_else(|e| panic!("{e}"));
    let lane = road
        .lane(THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let (s0, v, dt) = (30.0, 15.0, 0.05);
    let start = lane.point(s0, 0.0);
    let yaw0 = lane.heading_rad(s0);
    for i in 0..240 {
        let t = f64::from(i) * dt;
        let s = s0 + v * t;
        let in_lane = body(0, lane.point(s, 0.0), lane.heading_rad(s), v);
        let straight = [start[0] + v * t * yaw0.cos(), start[1] + v * t * yaw0.sin()];
        monitor
            .check(t, &[in_lane, body(1, straight, yaw0, v)], dt)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    assert_eq!(monitor.edge_contact_events(), near.as_slice());
}

/// A car entirely off the road beyond the curve's outer edge is in contact with it; one
/// beyond the road's open end, between the side edges' extensions, is not.
#[test]
fn off_the_curve_is_a_contact_and_beyond_the_open_end_is_not() {
    let road = lanes([0.0, 0.0]);
    let lane = road
        .lane(THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let s = 400.0;
    let mut monitor =
        SafetyMonitor::new(SafetyParams::default(), road.clone()).unwrap_or_else(|e| panic!("{e}"));
    let off = body(0, lane.point(s, -8.0), lane.heading_rad(s), 10.0);
    let r = monitor
        .check(0.0, &[off], 0.01)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(r.new_edge_contacts[0].edge, RoadEdge::Lower);
    let inner = body(1, lane.point(s, 8.0), lane.heading_rad(s), 10.0);
    let mut monitor =
        SafetyMonitor::new(SafetyParams::default(), road.clone()).unwrap_or_else(|e| panic!("{e}"));
    let r = monitor
        .check(0.0, &[inner], 0.01)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(r.new_edge_contacts[0].edge, RoadEdge::Upper);
    let end = lane.length_m();
    let beyond = body(2, lane.point(end + 10.0, 0.0), lane.heading_rad(end), 10.0);
    let mut monitor =
        SafetyMonitor::new(SafetyParams::default(), road.clone()).unwrap_or_else(|e| panic!("{e}"));
    let r = monitor
        .check(0.0, &[beyond], 0.01)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(r.new_edge_contacts.is_empty(), "{:?}", r.new_edge_contacts);
}
