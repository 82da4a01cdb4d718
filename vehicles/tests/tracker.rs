//! The tracker follows a straight road with a lane change and holds a speed profile.

use mergesim_types::PathPoint;
use vehicles::tracker::{Tracker, TrackerParams};
use vehicles::{PhysicsWorld, Vehicle, VehicleParams};

const LANE_WIDTH_M: f64 = 3.5;
const CHANGE_START_M: f64 = 100.0;
const CHANGE_LENGTH_M: f64 = 60.0;
const SLOW_DOWN_AT_M: f64 = 300.0;
const SLOW_DOWN_LENGTH_M: f64 = 60.0;

/// Reference path: y = W/2·(1 − cos(π (x − x0) / ℓ)) between x0 and x0 + ℓ (a smooth lane
/// change); speed 20 m/s, then a constant deceleration to 15 m/s over 60 m
/// (v² linear in x: (20² − 15²) / (2·60) ≈ 1.46 m/s²).
fn path_y(x: f64) -> f64 {
    let s = ((x - CHANGE_START_M) / CHANGE_LENGTH_M).clamp(0.0, 1.0);
    0.5 * LANE_WIDTH_M * (1.0 - (std::f64::consts::PI * s).cos())
}

fn path_speed(x: f64) -> f64 {
    let s = ((x - SLOW_DOWN_AT_M) / SLOW_DOWN_LENGTH_M).clamp(0.0, 1.0);
    (400.0 + s * (225.0 - 400.0)).sqrt()
}

#[test]
fn follows_lane_change_and_speed_profile() {
    for vehicle_name in vehicles::PRESET_NAMES {
        let params = VehicleParams::preset(vehicle_name).unwrap();
        let path: Vec<PathPoint> = (0..400)
            .map(|i| {
                let x = -10.0 + 2.0 * f64::from(i);
                PathPoint {
                    x_m: x,
                    y_m: path_y(x),
                    speed_mps: path_speed(x),
                    t_s: 0.0,
                }
            })
            .collect();
        let dt = 0.002;
        let mut world = PhysicsWorld::new(dt).unwrap();
        world.add_flat_ground(1000.0);
        let mut vehicle = Vehicle::spawn(&mut world, &params, 0.0, 0.0, 0.0, 20.0).unwrap();
        let mut tracker = Tracker::new(TrackerParams::default(), &params);

        let mut max_offset: f64 = 0.0;
        let mut max_offset_settled: f64 = 0.0;
        let mut max_speed_error_fast: f64 = 0.0;
        let mut max_speed_error_ramp: f64 = 0.0;
        let mut max_speed_error_slow: f64 = 0.0;
        let mut max_lat_accel: f64 = 0.0;
        for _ in 0..(25.0 / dt) as usize {
            let kin = vehicle.kinematics(&world);
            let controls = tracker.update(&kin, &path, dt);
            vehicle.set_controls(controls);
            vehicle.apply_forces(&mut world, 0.9);
            world.step();
            let kin = vehicle.kinematics(&world);
            // Lateral offset from the path; the path's slope is below 0.1 so this is the
            // distance to within 0.5 %.
            let offset = (kin.y_m - path_y(kin.x_m)).abs();
            max_offset = max_offset.max(offset);
            if kin.x_m > CHANGE_START_M + CHANGE_LENGTH_M + 40.0 {
                max_offset_settled = max_offset_settled.max(offset);
            }
            if kin.x_m < CHANGE_START_M {
                max_speed_error_fast = max_speed_error_fast.max((kin.speed_mps - 20.0).abs());
            }
            if kin.x_m > SLOW_DOWN_AT_M && kin.x_m < SLOW_DOWN_AT_M + SLOW_DOWN_LENGTH_M {
                let error = (kin.speed_mps - path_speed(kin.x_m)).abs();
                max_speed_error_ramp = max_speed_error_ramp.max(error);
            }
            if kin.x_m > SLOW_DOWN_AT_M + SLOW_DOWN_LENGTH_M + 20.0 {
                max_speed_error_slow = max_speed_error_slow.max((kin.speed_mps - 15.0).abs());
            }
            max_lat_accel = max_lat_accel.max(kin.accel_lat_mps2.abs());
        }
        let end = vehicle.kinematics(&world);
        println!(
            "{vehicle_name}: max offset {max_offset:.3} m, settled {max_offset_settled:.4} m, \
             speed error {max_speed_error_fast:.3}/{max_speed_error_ramp:.3}/{max_speed_error_slow:.3} m/s, \
             peak a_y {max_lat_accel:.2} m/s²"
        );
        assert!(
            end.x_m > SLOW_DOWN_AT_M + SLOW_DOWN_LENGTH_M + 60.0,
            "{vehicle_name}: got to {}",
            end.x_m
        );
        assert!(max_offset < 0.35, "{vehicle_name}: max offset {max_offset}");
        assert!(
            max_offset_settled < 0.05,
            "{vehicle_name}: settled offset {max_offset_settled}"
        );
        assert!(
            max_speed_error_fast < 0.2,
            "{vehicle_name}: {max_speed_error_fast}"
        );
        assert!(
            max_speed_error_ramp < 0.3,
            "{vehicle_name}: {max_speed_error_ramp}"
        );
        assert!(
            max_speed_error_slow < 0.2,
            "{vehicle_name}: {max_speed_error_slow}"
        );
        // The lane change needs a peak of W/2 (π/ℓ)² v² ≈ 1.9 m/s²; the tracker must not add much.
        assert!(max_lat_accel < 3.0, "{vehicle_name}: {max_lat_accel}");
    }
}

/// Target speed 0: the car stops and then stays put (brake hold, no creep, no chatter).
#[test]
fn stops_and_holds_without_creeping() {
    let params = VehicleParams::default();
    let dt = 0.002;
    let mut world = PhysicsWorld::new(dt).unwrap();
    world.add_flat_ground(500.0);
    let mut vehicle = Vehicle::spawn(&mut world, &params, 0.0, 0.0, 0.0, 8.0).unwrap();
    let mut tracker = Tracker::new(TrackerParams::default(), &params);
    let path: Vec<PathPoint> = (0..100)
        .map(|i| PathPoint {
            x_m: f64::from(i) * 2.0,
            y_m: 0.0,
            speed_mps: 0.0,
            t_s: 0.0,
        })
        .collect();
    let mut x_at_6s = None;
    for n in 0..(10.0 / dt) as usize {
        let kin = vehicle.kinematics(&world);
        let controls = tracker.update(&kin, &path, dt);
        vehicle.set_controls(controls);
        vehicle.apply_forces(&mut world, 0.8);
        world.step();
        let kin = vehicle.kinematics(&world);
        if n as f64 * dt >= 6.0 {
            assert!(
                kin.speed_mps < 0.01,
                "still moving at {}: {kin:?}",
                n as f64 * dt
            );
            let x0 = *x_at_6s.get_or_insert(kin.x_m);
            assert!((kin.x_m - x0).abs() < 0.01, "creeping: {} vs {x0}", kin.x_m);
        }
    }
}
