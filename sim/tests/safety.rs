//! Safety checks against closed forms: box–box gaps, head-on TTC, collision timing and episodes,
//! road-edge contacts in the merge taper.

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_4, PI};

use mergesim_types::MergeRoad;
use sim::safety::{BodyState, RoadEdge, SafetyError, SafetyMonitor, SafetyParams};

/// The road as lanes, as the world hands it to the monitor.
fn lanes(road: &MergeRoad) -> std::sync::Arc<mergesim_types::lanes::LaneRoad> {
    std::sync::Arc::new(road.lane_road().unwrap())
}

fn car(id: u32, x_m: f64, y_m: f64, yaw_rad: f64, vx_mps: f64, vy_mps: f64) -> BodyState {
    BodyState {
        id,
        x_m,
        y_m,
        yaw_rad,
        vx_mps,
        vy_mps,
        yaw_rate_radps: 0.0,
        length_m: 4.0,
        width_m: 2.0,
        height_m: 1.5,
    }
}

fn monitor() -> SafetyMonitor {
    SafetyMonitor::new(SafetyParams::default(), lanes(&MergeRoad::default())).unwrap()
}

/// Monitor that counts only true overlap as contact (no touching tolerance).
fn exact_monitor() -> SafetyMonitor {
    let params = SafetyParams {
        contact_tolerance_m: 0.0,
        ..SafetyParams::default()
    };
    SafetyMonitor::new(params, lanes(&MergeRoad::default())).unwrap()
}

/// Monitor without road edges, for pair tests placed anywhere.
fn pair_monitor() -> SafetyMonitor {
    let params = SafetyParams {
        check_road_edges: false,
        ..SafetyParams::default()
    };
    SafetyMonitor::new(params, lanes(&MergeRoad::default())).unwrap()
}

/// Rotates a body about the origin by `angle_rad` and then translates it.
fn moved(b: BodyState, angle_rad: f64, dx_m: f64, dy_m: f64) -> BodyState {
    let (s, c) = angle_rad.sin_cos();
    BodyState {
        x_m: c * b.x_m - s * b.y_m + dx_m,
        y_m: s * b.x_m + c * b.y_m + dy_m,
        yaw_rad: b.yaw_rad + angle_rad,
        vx_mps: c * b.vx_mps - s * b.vy_mps,
        vy_mps: s * b.vx_mps + c * b.vy_mps,
        ..b
    }
}

fn single_gap(a: BodyState, b: BodyState) -> f64 {
    let mut m = pair_monitor();
    let report = m.check(0.0, &[a, b], 0.01).unwrap();
    assert!(!report.pairs[0].gap_is_lower_bound);
    report.pairs[0].gap_m
}

#[test]
fn gap_of_axis_aligned_boxes_equals_analytic_distance() {
    // Side by side along x: faces 4.0 - 2 - 2 = 0.7 m apart after a 4.7 m offset.
    let a = car(0, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert!((single_gap(a, car(1, 4.7, 0.0, 0.0, 0.0, 0.0)) - 0.7).abs() < 1e-5);
    // Diagonal, corner to corner: offsets beyond contact dx = 0.3, dy = 0.4 -> 0.5 m.
    let gap = single_gap(a, car(1, 4.3, 2.4, 0.0, 0.0, 0.0));
    assert!((gap - 0.5).abs() < 1e-5, "{gap}");
}

#[test]
fn gap_of_rotated_boxes_equals_analytic_distance_in_any_frame() {
    // B turned by 45° with its corner pointing at A's front face: the corner reaches
    // (half_length + half_width)/√2 = 3/√2 in -x from B's centre.
    let corner_reach_m = 3.0 * FRAC_1_SQRT_2;
    let a = car(0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let b = car(1, 2.0 + 0.37 + corner_reach_m, 0.2, FRAC_PI_4, 0.0, 0.0);
    let expected_m = 0.37;
    assert!((single_gap(a, b) - expected_m).abs() < 1e-5);
    // The same configuration rotated and moved far down the road: the gap is invariant.
    for (angle, dx, dy) in [(0.3, 500.0, 3.0), (-2.0, 650.0, -1.0), (PI, 120.0, 5.25)] {
        let gap = single_gap(moved(a, angle, dx, dy), moved(b, angle, dx, dy));
        assert!((gap - expected_m).abs() < 1e-4, "angle {angle}: {gap}");
    }
}

#[test]
fn ttc_head_on_equals_gap_over_closing_speed() {
    // Head-on in one lane: gap 30 - 4 = 26 m, closing 10 + 6 = 16 m/s.
    let a = car(0, 100.0, 1.75, 0.0, 10.0, 0.0);
    let b = car(1, 130.0, 1.75, PI, -6.0, 0.0);
    let mut m = monitor();
    let report = m.check(0.0, &[a, b], 0.01).unwrap();
    let ttc = report.pairs[0].ttc_s.unwrap();
    assert!((ttc - 26.0 / 16.0).abs() < 1e-3, "{ttc}");

    // Following: 20 m/s behind 15 m/s with a 12 m gap -> 2.4 s.
    let mut m = monitor();
    let a = car(0, 300.0, 5.25, 0.0, 20.0, 0.0);
    let b = car(1, 316.0, 5.25, 0.0, 15.0, 0.0);
    let ttc = m.check(0.0, &[a, b], 0.01).unwrap().pairs[0].ttc_s.unwrap();
    assert!((ttc - 2.4).abs() < 1e-3, "{ttc}");

    // Oblique approach in a rotated frame: same TTC.
    let mut m = pair_monitor();
    let a = moved(car(0, 0.0, 0.0, 0.0, 10.0, 0.0), 0.8, 400.0, 2.0);
    let b = moved(car(1, 30.0, 0.0, PI, -6.0, 0.0), 0.8, 400.0, 2.0);
    let ttc = m.check(0.0, &[a, b], 0.01).unwrap().pairs[0].ttc_s.unwrap();
    assert!((ttc - 26.0 / 16.0).abs() < 1e-3, "{ttc}");
}

#[test]
fn ttc_is_none_when_separating_or_beyond_horizon() {
    let mut m = monitor();
    // Moving apart.
    let a = car(0, 0.0, 1.75, 0.0, 10.0, 0.0);
    let b = car(1, 20.0, 1.75, 0.0, 15.0, 0.0);
    assert_eq!(m.check(0.0, &[a, b], 0.01).unwrap().pairs[0].ttc_s, None);
    // Closing but contact after the 10 s horizon: gap 96 m at 5 m/s = 19.2 s.
    let a = car(0, 0.0, 1.75, 0.0, 20.0, 0.0);
    let b = car(1, 100.0, 1.75, 0.0, 15.0, 0.0);
    let report = m.check(0.01, &[a, b], 0.01).unwrap();
    assert_eq!(report.pairs[0].ttc_s, None);
    // Parallel lanes at the same speed never touch.
    let a = car(0, 0.0, 1.75, 0.0, 20.0, 0.0);
    let b = car(1, 1.0, 5.25, 0.0, 20.0, 0.0);
    assert_eq!(m.check(0.02, &[a, b], 0.01).unwrap().pairs[0].ttc_s, None);
}

#[test]
fn collision_is_detected_at_the_first_overlapping_instant_once_per_episode() {
    // A at 20 m/s, B at 15 m/s ahead: gap 12 m closes at 5 m/s -> contact at t = 2.4 s.
    let dt = 0.05;
    let mut m = monitor();
    let mut contact_steps = Vec::new();
    for k in 0..80 {
        let t = k as f64 * dt;
        let a = car(0, 20.0 * t, 5.25, 0.0, 20.0, 0.0);
        let b = car(1, 16.0 + 15.0 * t, 5.25, 0.0, 15.0, 0.0);
        let report = m.check(t, &[a, b], dt).unwrap();
        if !report.new_collisions.is_empty() {
            contact_steps.push(k);
        }
    }
    // First instant with overlap: 5 t > 12 -> t > 2.4 -> k = 49 (t = 2.45 s); touching at
    // exactly 2.4 s (k = 48) is within f32 rounding, so accept either, but only one event.
    assert_eq!(contact_steps.len(), 1, "{contact_steps:?}");
    let summary = m.summary();
    assert_eq!(summary.collisions.len(), 1);
    let event = &summary.collisions[0];
    assert!(
        event.t_s >= 2.4 - 1e-9 && event.t_s <= 2.45 + 1e-9,
        "{}",
        event.t_s
    );
    assert_eq!((event.id_a, event.id_b), (0, 1));
    let t_contact = event.t_contact_estimate_s.unwrap();
    assert!((t_contact - 2.4).abs() < 1e-3, "{t_contact}");
    assert!((event.relative_speed_mps - 5.0).abs() < 1e-12);
    assert_eq!(summary.min_gap_m, Some(0.0));
    assert_eq!(summary.min_ttc_s, Some(0.0));
    assert!(!summary.near_miss);

    // Separate, then touch again: a second episode.
    let far_a = car(0, 0.0, 5.25, 0.0, 0.0, 0.0);
    let far_b = car(1, 50.0, 5.25, 0.0, 0.0, 0.0);
    m.check(10.0, &[far_a, far_b], dt).unwrap();
    let touch_b = car(1, 3.9, 5.25, 0.0, 0.0, 0.0);
    let report = m.check(10.05, &[far_a, touch_b], dt).unwrap();
    assert_eq!(report.new_collisions.len(), 1);
    assert_eq!(report.new_collisions[0].t_contact_estimate_s, None);
    assert_eq!(m.summary().collisions.len(), 2);
    assert_eq!(m.summary().pairs[0].collisions, 2);
}

#[test]
fn near_miss_tet_and_min_gap_without_collision() {
    // Following at 20 vs 15 m/s, B brakes hard enough that the gap never closes:
    // gap(t) = 12 - 5 t + 0.5·a·t² with a = 1.5 m/s² -> min gap 12 - 25/3 ≈ 3.667 m at t = 10/3 s.
    let dt = 0.01;
    let accel = 1.5;
    let mut m = monitor();
    let mut expected_tet = 0.0;
    let mut expected_min_ttc = f64::INFINITY;
    for k in 0..700 {
        let t = k as f64 * dt;
        let vb = 15.0 + accel * t;
        let a = car(0, 20.0 * t, 5.25, 0.0, 20.0, 0.0);
        let b = car(1, 16.0 + 15.0 * t + 0.5 * accel * t * t, 5.25, 0.0, vb, 0.0);
        let gap = 12.0 - 5.0 * t + 0.5 * accel * t * t;
        let closing = 20.0 - vb;
        if closing > 0.0 {
            expected_min_ttc = expected_min_ttc.min(gap / closing);
            if gap / closing < 1.5 {
                expected_tet += dt;
            }
        }
        m.check(t, &[a, b], dt).unwrap();
    }
    let s = m.summary();
    assert!(s.collisions.is_empty());
    // The closed-form minimum is at t = 10/3 s, an exact sampling instant up to 1e-5 m.
    let min_gap = s.min_gap_m.unwrap();
    assert!((min_gap - (12.0 - 25.0 / 3.0)).abs() < 1e-4, "{min_gap}");
    // Constant-velocity TTC is gap / closing at each instant; its minimum (≈ 2.21 s at
    // t ≈ 1.12 s, from d/dt (gap/closing) = 0) is above the threshold.
    assert!((expected_min_ttc - 2.211).abs() < 1e-3);
    assert!((s.min_ttc_s.unwrap() - expected_min_ttc).abs() < 1e-3);
    assert_eq!(s.tet_s, 0.0);
    assert!(!s.near_miss);
    assert_eq!(expected_tet, 0.0);

    // Start closer (gap 5 m): TTC 1.0 s < 1.5 s -> near miss, with TET equal to the time the
    // closed form spends below the threshold.
    let mut m = monitor();
    let mut expected_tet = 0.0;
    let accel = 3.0;
    for k in 0..700 {
        let t = k as f64 * dt;
        let vb = 15.0 + accel * t;
        let a = car(0, 20.0 * t, 5.25, 0.0, 20.0, 0.0);
        let b = car(1, 9.0 + 15.0 * t + 0.5 * accel * t * t, 5.25, 0.0, vb, 0.0);
        let gap = 5.0 - 5.0 * t + 0.5 * accel * t * t;
        let closing = 20.0 - vb;
        if closing > 0.0 && gap / closing < 1.5 {
            expected_tet += dt;
        }
        m.check(t, &[a, b], dt).unwrap();
    }
    let s = m.summary();
    assert!(s.collisions.is_empty());
    assert!(s.near_miss);
    assert!(expected_tet > 0.1);
    // Instants exactly at the threshold could fall either way in f32: at most one differs.
    assert!(
        (s.tet_s - expected_tet).abs() <= dt + 1e-9,
        "{} vs {expected_tet}",
        s.tet_s
    );
    assert_eq!(s.pairs[0].tet_s, s.tet_s);
}

#[test]
fn far_pairs_report_a_lower_bound_that_does_not_change_the_minimum() {
    let mut m = pair_monitor();
    let a = car(0, 0.0, 0.0, 0.0, 0.0, 0.0);
    // First visit: exact (no minimum yet).
    let r = m
        .check(0.0, &[a, car(1, 10.0, 0.0, 0.0, 0.0, 0.0)], 0.1)
        .unwrap();
    assert!(!r.pairs[0].gap_is_lower_bound);
    assert!((r.pairs[0].gap_m - 6.0).abs() < 1e-5);
    // Far away: only the bound, which is below the true gap (96 m) and above the minimum.
    let r = m
        .check(0.1, &[a, car(1, 100.0, 0.0, 0.0, 0.0, 0.0)], 0.1)
        .unwrap();
    assert!(r.pairs[0].gap_is_lower_bound);
    assert!(r.pairs[0].gap_m <= 96.0 && r.pairs[0].gap_m > 6.0);
    assert!((m.summary().min_gap_m.unwrap() - 6.0).abs() < 1e-5);
}

#[test]
fn box_crossing_the_lower_edge_in_the_taper_is_an_edge_contact() {
    let road = MergeRoad::default();
    let k = road.taper_slope();
    let heading = k.atan();
    let x = 0.5 * (road.merge_start_x_m + road.merge_end_x_m);
    let edge_y = road.lower_edge_y_m(x);
    // A box aligned with the taper: perpendicular distance from its centre to the edge line is
    // (y - edge_y)·cos(heading); contact iff that is below the half width (1 m). Probed at
    // ±0.5 mm: parry computes in f32 (measured resolution here better than 0.03 mm).
    let at = |offset_m: f64| BodyState {
        yaw_rad: heading,
        ..car(0, x, edge_y + offset_m / heading.cos(), heading, 20.0, 0.0)
    };
    let mut m = exact_monitor();
    let r = m.check(0.0, &[at(1.0005)], 0.01).unwrap();
    assert!(r.new_edge_contacts.is_empty());
    let r = m.check(0.01, &[at(0.9995)], 0.01).unwrap();
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(r.new_edge_contacts[0].edge, RoadEdge::Lower);
    assert_eq!(r.new_edge_contacts[0].t_s, 0.01);
    // Still touching: same episode.
    let r = m.check(0.02, &[at(0.5)], 0.01).unwrap();
    assert!(r.new_edge_contacts.is_empty());
    // Entirely beyond the edge (off the road): still the same episode, no new event.
    let r = m.check(0.03, &[at(-3.0)], 0.01).unwrap();
    assert!(r.new_edge_contacts.is_empty());
    // Back on the road, then touching again: a second episode.
    m.check(0.04, &[at(1.5)], 0.01).unwrap();
    let r = m.check(0.05, &[at(0.9)], 0.01).unwrap();
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(m.summary().edge_contacts.len(), 2);
}

#[test]
fn upper_edge_and_off_road_boxes_are_edge_contacts() {
    let road = MergeRoad::default();
    let mut m = monitor();
    // A box in the upper lane touching the upper edge (half width 1 m).
    let r = m
        .check(
            0.0,
            &[car(3, 50.0, road.y_upper_m() - 0.99, 0.0, 20.0, 0.0)],
            0.01,
        )
        .unwrap();
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(r.new_edge_contacts[0].edge, RoadEdge::Upper);
    // A box completely below the lower edge before the taper, never having crossed it.
    let mut m = monitor();
    let r = m
        .check(0.0, &[car(4, 50.0, -5.0, 0.0, 20.0, 0.0)], 0.01)
        .unwrap();
    assert_eq!(r.new_edge_contacts.len(), 1);
    assert_eq!(r.new_edge_contacts[0].edge, RoadEdge::Lower);
    // Lane centres are clear of both edges.
    let mut m = monitor();
    let r = m
        .check(
            0.0,
            &[
                car(
                    0,
                    50.0,
                    road.lane_center_y_m(mergesim_types::Lane::Lower),
                    0.0,
                    20.0,
                    0.0,
                ),
                car(
                    1,
                    80.0,
                    road.lane_center_y_m(mergesim_types::Lane::Upper),
                    0.0,
                    20.0,
                    0.0,
                ),
            ],
            0.01,
        )
        .unwrap();
    assert!(r.new_edge_contacts.is_empty());
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut m = monitor();
    let a = car(1, 0.0, 1.75, 0.0, 0.0, 0.0);
    let b = car(0, 10.0, 1.75, 0.0, 0.0, 0.0);
    assert!(matches!(
        m.check(0.0, &[a, b], 0.01),
        Err(SafetyError::UnsortedBodies { .. })
    ));
    let nan = BodyState { x_m: f64::NAN, ..b };
    assert!(matches!(
        m.check(0.0, &[nan], 0.01),
        Err(SafetyError::InvalidBody { field: "x_m", .. })
    ));
    m.check(1.0, &[b], 0.01).unwrap();
    assert!(matches!(
        m.check(1.0, &[b], 0.01),
        Err(SafetyError::InvalidTime { .. })
    ));
    let bad = SafetyParams {
        ttc_threshold_s: -1.0,
        ..SafetyParams::default()
    };
    assert!(SafetyMonitor::new(bad, lanes(&MergeRoad::default())).is_err());
}

#[test]
fn summary_serialises_with_the_documented_fields() {
    let mut m = monitor();
    m.check(
        0.0,
        &[
            car(0, 0.0, 1.75, 0.0, 20.0, 0.0),
            car(1, 10.0, 1.75, 0.0, 15.0, 0.0),
        ],
        0.01,
    )
    .unwrap();
    let json = serde_json::to_value(m.summary()).unwrap();
    for field in [
        "collisions",
        "min_gap_m",
        "min_ttc_s",
        "near_miss",
        "tet_s",
        "edge_contacts",
    ] {
        assert!(json.get(field).is_some(), "missing {field}");
    }
    let back: sim::safety::SafetySummary = serde_json::from_value(json).unwrap();
    assert_eq!(back, m.summary());
}

#[test]
fn touching_within_the_tolerance_is_contact() {
    // Rapier brings colliding boxes to rest touching, not overlapping: a gap below
    // `contact_tolerance_m` (default 1 cm) is contact, a larger one is not.
    let tolerance_m = SafetyParams::default().contact_tolerance_m;
    let mut m = pair_monitor();
    let length_m = car(0, 0.0, 0.0, 0.0, 0.0, 0.0).length_m;
    let r = m
        .check(
            0.0,
            &[
                car(0, 0.0, 0.0, 0.0, 0.0, 0.0),
                car(1, length_m + 2.0 * tolerance_m, 0.0, 0.0, 0.0, 0.0),
            ],
            0.01,
        )
        .unwrap();
    assert!(r.new_collisions.is_empty());
    let r = m
        .check(
            0.01,
            &[
                car(0, 0.0, 0.0, 0.0, 0.0, 0.0),
                car(1, length_m + 0.5 * tolerance_m, 0.0, 0.0, 0.0, 0.0),
            ],
            0.01,
        )
        .unwrap();
    assert_eq!(r.new_collisions.len(), 1);
}

#[test]
fn a_vehicle_exposed_to_two_pairs_at_once_counts_its_time_once() {
    // B sits between A (behind, closing at 5 m/s) and C (ahead, which B closes on at 5 m/s);
    // both gaps start at 4 m and then stay below TTC 1.5 s for the whole run. The run's TET and
    // each pair's count every instant; so does B's own exposure, once, not twice.
    let dt = 0.01;
    let mut m = pair_monitor();
    for k in 0..50 {
        let t = k as f64 * dt;
        let a = car(0, 20.0 * t, 5.25, 0.0, 20.0, 0.0);
        let b = car(1, 8.0 + 15.0 * t, 5.25, 0.0, 15.0, 0.0);
        let c = car(2, 16.0 + 10.0 * t, 5.25, 0.0, 10.0, 0.0);
        m.check(t, &[a, b, c], dt).unwrap();
    }
    let s = m.summary();
    assert!(s.collisions.is_empty());
    assert!((s.tet_s - 0.5).abs() < 1e-9, "{}", s.tet_s);
    let exposure: std::collections::BTreeMap<u32, f64> = s.vehicle_tet_s.iter().copied().collect();
    for id in 0..3 {
        assert!((exposure[&id] - 0.5).abs() < 1e-9, "{id}: {exposure:?}");
    }
    // Summed over the vehicles (Minderhoud & Bovy): three vehicles exposed for 0.5 s each.
    let total: f64 = s.vehicle_tet_s.iter().map(|(_, t)| t).sum();
    assert!((total - 1.5).abs() < 1e-9);
}
