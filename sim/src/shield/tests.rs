//! The RSS rules against hand-computed values, and the shield intervening exactly when a pair
//! is dangerous, with the response its blame time calls for.

use mergesim_types::lanes::{LaneRoad, merge_road_spec};
use mergesim_types::{
    Decision, MergeRoad, Neighbour, Observation, PathPoint, VehicleShape, VehicleState,
};

use super::rss_rules::{safe_lateral_gap_m, safe_longitudinal_gap_m};
use super::*;

const TOL: f64 = 1e-9;

#[test]
fn the_safe_longitudinal_gap_is_definition_1() {
    let p = RssParams::default();
    // 20 → 20 m/s, ρ = 1 s: 20 + 1.75 + 23.5²/8 − 20²/16 = 65.78125 m.
    assert!((safe_longitudinal_gap_m(20.0, 20.0, 1.0, &p) - 65.781_25).abs() < TOL);
    // ρ = 2 s: 40 + 7 + 27²/8 − 25 = 113.125 m.
    assert!((safe_longitudinal_gap_m(20.0, 20.0, 2.0, &p) - 113.125).abs() < TOL);
    // A front car much faster: 10 + 1.75 + 13.5²/8 − 30²/16 < 0, so 0.
    assert_eq!(safe_longitudinal_gap_m(10.0, 30.0, 1.0, &p), 0.0);
}

#[test]
fn the_safe_lateral_gap_is_definition_7() {
    let p = RssParams::default();
    // No lateral speeds, ρ 1 s and 2 s: 0.1 + (0.1 + 0.2²/1.6) + (0.4 + 0.4²/1.6) = 0.725 m.
    assert!((safe_lateral_gap_m(0.0, 1.0, 0.0, 2.0, &p) - 0.725).abs() < TOL);
    // The left car closing at 1 m/s: its approach 1 + 0.1 + 1.2²/1.6 = 2.0 m; total 2.6 m.
    assert!((safe_lateral_gap_m(1.0, 1.0, 0.0, 2.0, &p) - 2.6).abs() < TOL);
    // Moving away at 1 m/s it approaches −1 + 0.1 − 0.8²/1.6 = −1.3 m: the sum −0.8 m is cut
    // to 0, leaving the margin.
    assert!((safe_lateral_gap_m(-1.0, 1.0, 0.0, 2.0, &p) - 0.1).abs() < TOL);
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let p = RssParams {
        brake_min_mps2: 0.0,
        ..RssParams::default()
    };
    assert!(
        p.validate()
            .unwrap_err()
            .to_string()
            .contains("rss.brake_min_mps2")
    );
    let p = RssParams {
        brake_max_mps2: 3.0,
        ..RssParams::default()
    };
    let e = p.validate().unwrap_err().to_string();
    assert!(
        e.contains("rss.brake_max_mps2") && e.contains("brake_min"),
        "{e}"
    );
    assert!(RssParams::default().validate().is_ok());
}

/// A 4.5 m × 1.8 m car.
fn shape() -> VehicleShape {
    VehicleShape {
        length_m: 4.5,
        width_m: 1.8,
        wheelbase_m: 2.6,
        max_brake_decel_mps2: 7.0,
    }
}

fn state(x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> VehicleState {
    VehicleState {
        x_m,
        y_m,
        yaw_rad,
        speed_mps,
    }
}

/// The merge road's upper-lane centre (y = 5.25 m) and lower-lane centre (1.75 m).
const UPPER_Y_M: f64 = 5.25;
const LOWER_Y_M: f64 = 1.75;

/// 21 points 3 m apart from x = 0 at 20 m/s, bending from the upper lane's centre to
/// `end_y_m` linearly.
fn decision(end_y_m: f64) -> Decision {
    let path = (0..=20)
        .map(|i| PathPoint {
            x_m: 3.0 * i as f64,
            y_m: UPPER_Y_M + (end_y_m - UPPER_Y_M) * i as f64 / 20.0,
            speed_mps: 20.0,
            t_s: 3.0 * i as f64 / 20.0,
        })
        .collect();
    Decision {
        path,
        broadcast: None,
        fallback: None,
        degraded_mode: None,
    }
}

/// Applies `shield` at t = 0 for the ego at (0, 5.25) heading +x at 20 m/s, with `others`.
fn shielded(
    shield: &mut RssShield,
    lanes: &LaneRoad,
    others: &[VehicleState],
    end_y_m: f64,
) -> (Decision, Vec<Intervention>) {
    let neighbours: Vec<Neighbour> = others
        .iter()
        .enumerate()
        .map(|(k, s)| Neighbour {
            id: k as u32 + 1,
            state: *s,
            shape: shape(),
        })
        .collect();
    let obs = Observation {
        time_s: 0.0,
        ego_id: 0,
        ego: state(0.0, UPPER_Y_M, 0.0, 20.0),
        ego_shape: shape(),
        target_speed_mps: 20.0,
        mu: 0.8,
        lanes,
        neighbours: &neighbours,
        shared_paths: &[],
    };
    let mut d = decision(end_y_m);
    let started = shield.apply(&obs, &mut d);
    (d, started)
}

fn lanes() -> LaneRoad {
    LaneRoad::new(&merge_road_spec(&MergeRoad::default())).unwrap()
}

#[test]
fn a_car_close_ahead_in_the_lane_is_dangerous_and_the_shield_brakes() {
    let lanes = lanes();
    let mut shield = RssShield::new(RssParams::default(), 0.1);
    // 40 m ahead: a 35.5 m gap, 65.78 m needed; the lateral gap is −1.8 m.
    let (d, started) = shielded(
        &mut shield,
        &lanes,
        &[state(40.0, UPPER_Y_M, 0.0, 20.0)],
        UPPER_Y_M,
    );
    assert_eq!(started.len(), 1, "{started:?}");
    assert_eq!(started[0].other, Some(1));
    // First seen already dangerous: both responses.
    assert_eq!(started[0].responses.name(), "longitudinal+lateral");
    assert!(!started[0].safety.lon_safe && !started[0].safety.lat_safe);
    // Braking at 4 m/s² from 20 m/s: 30 m along the path, √(400 − 240) m/s.
    let at_30m = &d.path[10];
    assert!(
        (at_30m.speed_mps - 160f64.sqrt()).abs() < 1e-9,
        "{at_30m:?}"
    );
    assert_eq!(d.path[0].speed_mps, 20.0);
    // Times follow the slower speeds: later than the planner's.
    assert!(at_30m.t_s > 1.5 + 0.1, "{at_30m:?}");
    // The same situation next tick: the response holds, no new intervention.
    let (d2, again) = shielded(
        &mut shield,
        &lanes,
        &[state(40.0, UPPER_Y_M, 0.0, 20.0)],
        UPPER_Y_M,
    );
    assert!(again.is_empty());
    assert_eq!(d2.path[10].speed_mps, at_30m.speed_mps);
}

#[test]
fn a_car_beside_in_the_next_lane_or_far_ahead_is_not_dangerous_and_nothing_changes() {
    let lanes = lanes();
    for other in [
        // Beside in the lower lane: lateral gap 3.5 − 1.8 = 1.7 m ≥ 0.725 m.
        state(0.0, LOWER_Y_M, 0.0, 20.0),
        // 100 m ahead in the lane: 95.5 m ≥ 65.78 m.
        state(100.0, UPPER_Y_M, 0.0, 20.0),
    ] {
        let mut shield = RssShield::new(RssParams::default(), 0.1);
        let (d, started) = shielded(&mut shield, &lanes, &[other], UPPER_Y_M);
        assert!(started.is_empty(), "{other:?}: {started:?}");
        assert_eq!(d, decision(UPPER_Y_M), "{other:?}");
    }
}

#[test]
fn the_blame_time_picks_the_response() {
    let lanes = lanes();
    let mut shield = RssShield::new(RssParams::default(), 0.1);
    // Tick 1: 20 m ahead in the lower lane: longitudinally unsafe (15.5 m < 65.78 m),
    // laterally safe: not dangerous, remembered.
    let beside = state(20.0, LOWER_Y_M, 0.0, 20.0);
    let (_, started) = shielded(&mut shield, &lanes, &[beside], UPPER_Y_M);
    assert!(started.is_empty());
    // Tick 2: it has drifted to y = 3.5 m (side gap 1.75 − 1.8 < 0): dangerous. The lateral
    // gap was the safe one before, so the response is lateral only: a path veering right
    // toward it is held at the ego's lateral position, and its speeds are left alone.
    let drifted = state(20.0, 3.5, 0.0, 20.0);
    let (d, started) = shielded(&mut shield, &lanes, &[drifted], 2.25);
    assert_eq!(started.len(), 1, "{started:?}");
    assert_eq!(started[0].responses.name(), "lateral");
    for p in &d.path {
        assert!((p.y_m - UPPER_Y_M).abs() < 1e-9, "{p:?}");
        assert_eq!(p.speed_mps, 20.0);
    }
    // A path veering left, away from it (and not toward the road's upper edge at 7 m), is not
    // held.
    let (d, _) = shielded(&mut shield, &lanes, &[drifted], 5.5);
    assert_eq!(d, decision(5.5));
    // Back in its lane: no longer dangerous; drifting again is a new intervention.
    let (_, started) = shielded(&mut shield, &lanes, &[beside], UPPER_Y_M);
    assert!(started.is_empty());
    let (_, started) = shielded(&mut shield, &lanes, &[drifted], UPPER_Y_M);
    assert_eq!(started.len(), 1);
}

#[test]
fn a_car_behind_does_not_make_the_shielded_car_brake() {
    // 30 m behind in the lane at 20 m/s: dangerous (its safe gap, ρ = 2 s, is 113.125 m), but
    // the longitudinal duty is the rear car's; the lateral response holds the lane.
    let lanes = lanes();
    let mut shield = RssShield::new(RssParams::default(), 0.1);
    let (d, started) = shielded(
        &mut shield,
        &lanes,
        &[state(-30.0, UPPER_Y_M, 0.0, 20.0)],
        UPPER_Y_M,
    );
    assert_eq!(started.len(), 1);
    assert!((started[0].safety.safe_lon_gap_m - 113.125).abs() < TOL);
    assert!(d.path.iter().all(|p| p.speed_mps == 20.0));
}
