//! Bitwise determinism: identical runs give identical trajectories.

use mergesim_types::{Lane, MergeRoad, PathPoint};
use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};
use vehicles::tracker::{Tracker, TrackerParams};
use vehicles::{PhysicsWorld, Vehicle, VehicleParams};

/// Three cars on the merge road, two of them converging on the same lane, tracked for 4 s.
fn run_merge_road() -> Vec<u64> {
    let road = MergeRoad::default();
    let dt = 0.002;
    let mut world = PhysicsWorld::new(dt).unwrap();
    world.add_lane_road(&road.lane_road().expect("the default road is valid"));
    let starts = [
        ("bmw_320i", 0.0, Lane::Lower, 20.0),
        ("ford_escort", 5.0, Lane::Upper, 15.0),
        ("vw_vanagon", 40.0, Lane::Upper, 18.0),
    ];
    let mut cars: Vec<(Vehicle, Tracker, Vec<PathPoint>)> = starts
        .iter()
        .map(|&(name, x, lane, v)| {
            let params = VehicleParams::preset(name).unwrap();
            let y = road.lane_center_y_m(lane);
            let vehicle = Vehicle::spawn(&mut world, &params, x, y, 0.0, v).unwrap();
            let tracker = Tracker::new(TrackerParams::default(), &params);
            let target_y = road.lane_center_y_m(Lane::Upper);
            let path = (0..60)
                .map(|i| {
                    let px = x + 2.0 * f64::from(i);
                    PathPoint {
                        x_m: px,
                        y_m: y + (target_y - y) * (f64::from(i) / 30.0).min(1.0),
                        speed_mps: v,
                        t_s: 0.0,
                    }
                })
                .collect();
            (vehicle, tracker, path)
        })
        .collect();
    let mut bits = Vec::new();
    for _ in 0..2000 {
        for (vehicle, tracker, path) in &mut cars {
            let kin = vehicle.kinematics(&world);
            let controls = tracker.update(&kin, path, dt);
            vehicle.set_controls(controls);
            vehicle.apply_forces(&mut world, 0.85);
        }
        world.step();
        for (vehicle, _, _) in &cars {
            let k = vehicle.kinematics(&world);
            for v in [
                k.x_m,
                k.y_m,
                k.z_m,
                k.yaw_rad,
                k.pitch_rad,
                k.roll_rad,
                k.speed_mps,
                k.yaw_rate_radps,
                k.sideslip_rad,
                k.accel_long_mps2,
                k.accel_lat_mps2,
                k.steer_rad,
            ] {
                bits.push(v.to_bits());
            }
            for w in vehicle.wheel_telemetry() {
                bits.push(w.spin_radps.to_bits());
                bits.push(w.fy_n.to_bits());
            }
        }
    }
    bits
}

#[test]
fn identical_runs_are_bitwise_identical() {
    let a = run_merge_road();
    let b = run_merge_road();
    assert_eq!(a.len(), b.len());
    let first_difference = a.iter().zip(&b).position(|(x, y)| x != y);
    assert_eq!(first_difference, None);
}

#[test]
fn identical_maneuvers_are_bitwise_identical() {
    let cfg = ManeuverConfig {
        kind: ManeuverKind::StepSteer,
        speed_mps: 22.0,
        steer_rad: 0.03,
        duration_s: 4.0,
        trace_period_s: 0.01,
        ..ManeuverConfig::default()
    };
    let a = serde_json::to_string(&run_maneuver(&cfg).unwrap()).unwrap();
    let b = serde_json::to_string(&run_maneuver(&cfg).unwrap()).unwrap();
    // serde_json writes shortest round-trip representations, so equal text ⇔ equal bits.
    assert_eq!(a, b);
}
