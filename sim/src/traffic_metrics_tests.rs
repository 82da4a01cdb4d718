use std::sync::Arc;

use mergesim_types::MergeRoad;
use mergesim_types::lanes::{
    ENDING_LANE_ID, LaneRoad, OnRampParams, THROUGH_LANE_ID, on_ramp_ids, on_ramp_spec,
};

use super::*;
use crate::safety::{CollisionEvent, SafetyMonitor, SafetyParams};

/// The default merge road: through lane y 3.5–7 m, ending lane y 0–3.5 m, the taper from
/// x = 160 to 260 m; arc length along the through lane is x + 50 m, so the section (20 m past
/// the lane's end) is at s = 330 m, x = 280 m.
fn merge_road() -> Arc<LaneRoad> {
    Arc::new(MergeRoad::default().lane_road().unwrap())
}

fn empty_safety(lanes: &Arc<LaneRoad>) -> SafetySummary {
    SafetyMonitor::new(SafetyParams::default(), lanes.clone())
        .unwrap()
        .summary()
}

fn vehicle(name: &str, class: &str, target_speed_mps: f64) -> (String, String, f64) {
    (name.to_string(), class.to_string(), target_speed_mps)
}

#[test]
fn ending_lanes_and_the_section_on_both_built_in_roads() {
    let merge = merge_road();
    let m = TrafficMetrics::new(merge, vec![]);
    assert_eq!(m.ending, BTreeSet::from([ENDING_LANE_ID]));
    assert_eq!(m.counted_lanes, BTreeSet::from([THROUGH_LANE_ID]));
    let (along, s_m) = m.section.unwrap();
    assert_eq!(along, THROUGH_LANE_ID);
    assert!((s_m - 330.0).abs() < 1e-9, "{s_m}");

    // On the on-ramp the ramp feeds only the acceleration lane, which ends closed: both are
    // ending lanes; both main lanes count at the section.
    let ramp = Arc::new(LaneRoad::new(&on_ramp_spec(&OnRampParams::default()).unwrap()).unwrap());
    let m = TrafficMetrics::new(ramp, vec![]);
    assert_eq!(
        m.ending,
        BTreeSet::from([on_ramp_ids::ACCELERATION, on_ramp_ids::RAMP])
    );
    assert_eq!(
        m.counted_lanes,
        BTreeSet::from([on_ramp_ids::MAIN_LEFT, on_ramp_ids::MAIN_RIGHT])
    );
}

#[test]
fn throughput_merging_and_delay_from_hand_made_tracks() {
    let lanes = merge_road();
    let mut m = TrafficMetrics::new(
        lanes.clone(),
        vec![
            vehicle("through", "pf-iso", 20.0),
            vehicle("merger", "pf-iso", 20.0),
            vehicle("slow", "idm", 20.0),
        ],
    );
    // `through` drives the through lane at 20 m/s from x = 250 m: it passes x = 280 m (the
    // section) at t = 1.5 s.
    // `merger` starts in the ending lane, crosses the divider (y = 3.5 m) between t = 1 and
    // 2 s, and passes the section at t = 3 s (x from 240 m at 20 m/s).
    // `slow` drives the through lane at 10 m/s against its 20 m/s target, far from the section.
    for k in 0..=8 {
        let t_s = 0.5 * k as f64;
        m.follow(0, t_s, [250.0 + 20.0 * t_s, 5.25], 20.0);
        let merger_y_m = if t_s < 2.0 { 1.75 } else { 5.25 };
        m.follow(1, t_s, [220.0 + 20.0 * t_s, merger_y_m], 20.0);
        m.follow(2, t_s, [0.0 + 10.0 * t_s, 5.25], 10.0);
    }
    let s = m.summary(&empty_safety(&lanes));
    let through = &s.vehicles[0];
    assert!(!through.merging);
    assert_eq!(through.merged_before_lane_end, None);
    assert!((through.crossed_section_at_s.unwrap() - 1.5).abs() < 1e-9);
    let merger = &s.vehicles[1];
    assert!(merger.merging);
    assert_eq!(merger.merged_at_s, Some(2.0));
    assert_eq!(merger.merged_before_lane_end, Some(true));
    // x = 220 + 20 t reaches 280 m at t = 3 s.
    assert!((merger.crossed_section_at_s.unwrap() - 3.0).abs() < 1e-9);
    // Two crossings 1.5 s apart: 2400 vehicles per hour.
    assert_eq!(s.crossings, 2);
    assert!((s.throughput_vph.unwrap() - 2400.0).abs() < 1e-6);
    assert_eq!((s.merging, s.merged_before_lane_end), (1, 1));
    // `slow`: 40 m in 4 s at 10 m/s, 2 s at its target: 2 s late, half its speed lost.
    let slow = &s.vehicles[2];
    assert!((slow.distance_m - 40.0).abs() < 1e-9);
    assert!((slow.delay_s - 2.0).abs() < 1e-9);
    assert!((slow.speed_loss - 0.5).abs() < 1e-12);
    assert!(s.vehicles[0].delay_s.abs() < 1e-9);
    // Classes sorted by name, each with its own vehicles.
    let names: Vec<&str> = s.classes.iter().map(|c| c.class.as_str()).collect();
    assert_eq!(names, ["idm", "pf-iso"]);
    assert_eq!(s.classes[1].vehicles, 2);
    assert_eq!(s.classes[1].crossed_section, 2);
    assert!((s.classes[0].mean_delay_s - 2.0).abs() < 1e-9);
    assert!((s.mean_delay_s.unwrap() - 2.0 / 3.0).abs() < 1e-9);
}

#[test]
fn an_edge_contact_before_merging_is_not_a_merge_before_the_lane_end() {
    let lanes = merge_road();
    let mut m = TrafficMetrics::new(
        lanes.clone(),
        vec![vehicle("late", "idm", 20.0), vehicle("never", "idm", 20.0)],
    );
    m.on_event(&SimEvent::EdgeContact {
        t_s: 1.0,
        vehicle: "late".into(),
        edge: crate::safety::RoadEdge::Lower,
    })
    .unwrap();
    for k in 0..=4 {
        let t_s = 0.5 * k as f64;
        let y_m = if t_s < 2.0 { 1.75 } else { 5.25 };
        m.follow(0, t_s, [200.0 + 20.0 * t_s, y_m], 20.0);
        m.follow(1, t_s, [100.0 + 20.0 * t_s, 1.75], 20.0);
    }
    let s = m.summary(&empty_safety(&lanes));
    assert_eq!(s.vehicles[0].merged_at_s, Some(2.0));
    assert_eq!(s.vehicles[0].merged_before_lane_end, Some(false));
    assert_eq!(s.vehicles[0].edge_contacts, 1);
    assert_eq!(s.vehicles[1].merged_at_s, None);
    assert_eq!(s.vehicles[1].merged_before_lane_end, Some(false));
    assert_eq!((s.merging, s.merged_before_lane_end), (2, 0));
    // One crossing or none: no throughput.
    assert_eq!(s.throughput_vph, None);
}

#[test]
fn safety_figures_per_vehicle_and_class() {
    let lanes = merge_road();
    let mut m = TrafficMetrics::new(
        lanes.clone(),
        vec![
            vehicle("a", "pf-iso", 20.0),
            vehicle("b", "pf-iso", 20.0),
            vehicle("c", "idm-mobil", 20.0),
        ],
    );
    for id in 0..3 {
        m.follow(id, 0.0, [0.0, 5.25], 20.0);
    }
    m.on_event(&SimEvent::ShieldIntervened {
        t_s: 0.0,
        vehicle: "a".into(),
        other: "c".into(),
        response: "longitudinal".into(),
        lon_gap_m: 10.0,
        safe_lon_gap_m: 30.0,
    })
    .unwrap();
    let mut safety = empty_safety(&lanes);
    safety.vehicle_tet_s = vec![(0, 1.5), (2, 0.25)];
    let collision = |id_a, id_b| CollisionEvent {
        t_s: 1.0,
        id_a,
        id_b,
        t_contact_estimate_s: None,
        relative_speed_mps: 1.0,
        caused_by_replay: false,
    };
    // a–b (both pf-iso: once for the class), b–c (once for each class).
    safety.collisions = vec![collision(0, 1), collision(1, 2)];
    let s = m.summary(&safety);
    assert_eq!(s.vehicles[0].tet_s, 1.5);
    assert_eq!(s.vehicles[1].tet_s, 0.0);
    assert_eq!(s.vehicles[1].collisions, 2);
    assert_eq!(s.vehicles[0].shield_interventions, 1);
    let idm = &s.classes[0];
    let pf = &s.classes[1];
    assert_eq!(
        (idm.class.as_str(), idm.collisions, idm.tet_s),
        ("idm-mobil", 1, 0.25)
    );
    assert_eq!(
        (pf.class.as_str(), pf.collisions, pf.tet_s),
        ("pf-iso", 2, 1.5)
    );
    assert_eq!(pf.shield_interventions, 1);
}
