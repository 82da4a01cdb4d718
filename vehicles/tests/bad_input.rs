//! Bad input gives errors naming the value, never a panic.

use mergesim_types::PathPoint;
use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};
use vehicles::tracker::{Tracker, TrackerParams};
use vehicles::{Controls, Kinematics, PhysicsWorld, Vehicle, VehicleParams};

#[test]
fn unknown_preset_lists_valid_names() {
    let err = VehicleParams::preset("trabant").unwrap_err().to_string();
    assert!(err.contains("trabant"), "{err}");
    for name in vehicles::PRESET_NAMES {
        assert!(err.contains(name), "{err}");
    }
    let cfg = ManeuverConfig {
        vehicle: "trabant".into(),
        ..ManeuverConfig::default()
    };
    let err = run_maneuver(&cfg).unwrap_err().to_string();
    assert!(err.contains("trabant"), "{err}");
}

#[test]
fn bad_friction_is_rejected_with_its_value() {
    for mu in [0.0, -0.5, f64::NAN, f64::INFINITY] {
        for kind in [
            ManeuverKind::SteadyState,
            ManeuverKind::StepSteer,
            ManeuverKind::Braking,
        ] {
            let cfg = ManeuverConfig {
                kind,
                mu,
                ..ManeuverConfig::default()
            };
            let err = run_maneuver(&cfg).unwrap_err().to_string();
            assert!(
                err.contains("mu") && err.contains(&format!("{mu}")),
                "{err}"
            );
        }
    }
}

/// A field name and how to break it.
type Breakage = (&'static str, fn(&mut VehicleParams));

#[test]
fn bad_vehicle_parameters_name_the_field() {
    let cases: [Breakage; 6] = [
        ("mass_kg", |p| p.mass_kg = f64::NAN),
        ("mass_kg", |p| p.mass_kg = -1093.0),
        ("yaw_inertia_kgm2", |p| p.yaw_inertia_kgm2 = 0.0),
        ("wheel_radius_m", |p| p.wheel_radius_m = f64::INFINITY),
        ("drive_torque_front_share", |p| {
            p.drive_torque_front_share = 1.5
        }),
        ("tire.p_cy1", |p| p.tire.p_cy1 = 2.5),
    ];
    for (field, mutate) in cases {
        let mut params = VehicleParams::default();
        mutate(&mut params);
        let err = params.validate().unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
        let mut world = PhysicsWorld::new(0.002).unwrap();
        world.add_flat_ground(100.0);
        let err = Vehicle::spawn(&mut world, &params, 0.0, 0.0, 0.0, 10.0)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains(field), "{field}: {err}");
        let cfg = ManeuverConfig {
            vehicle_params: Some(params),
            ..ManeuverConfig::default()
        };
        let err = run_maneuver(&cfg).unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
}

#[test]
fn bad_maneuver_fields_name_the_field() {
    let cases: [(&str, ManeuverConfig); 5] = [
        (
            "speed_mps",
            ManeuverConfig {
                speed_mps: f64::NAN,
                ..Default::default()
            },
        ),
        (
            "steer_rad",
            ManeuverConfig {
                steer_rad: 3.0,
                ..Default::default()
            },
        ),
        (
            "dt_s",
            ManeuverConfig {
                dt_s: 0.0,
                ..Default::default()
            },
        ),
        (
            "duration_s",
            ManeuverConfig {
                duration_s: -1.0,
                ..Default::default()
            },
        ),
        (
            "speed_mps",
            ManeuverConfig {
                speed_mps: -3.0,
                ..Default::default()
            },
        ),
    ];
    for (field, cfg) in cases {
        let err = run_maneuver(&cfg).unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
}

#[test]
fn spawn_rejects_bad_pose_and_missing_ground() {
    let mut world = PhysicsWorld::new(0.002).unwrap();
    world.add_flat_ground(100.0);
    let p = VehicleParams::default();
    let err = Vehicle::spawn(&mut world, &p, f64::NAN, 0.0, 0.0, 0.0)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("x_m"), "{err}");
    let err = Vehicle::spawn(&mut world, &p, 0.0, 0.0, 0.0, -5.0)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("speed_mps"), "{err}");
    let err = Vehicle::spawn(&mut world, &p, 500.0, 0.0, 0.0, 0.0)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("no road surface"), "{err}");
}

/// Non-finite controls, friction and paths must not panic nor poison the state.
#[test]
fn garbage_inputs_do_not_panic_or_produce_nan() {
    let mut world = PhysicsWorld::new(0.002).unwrap();
    world.add_flat_ground(200.0);
    world.add_flat_ground(f64::NAN);
    let p = VehicleParams::default();
    let mut vehicle = Vehicle::spawn(&mut world, &p, 0.0, 0.0, 0.0, 10.0).unwrap();
    let mut tracker = Tracker::new(TrackerParams::default(), &p);
    let nan_path = [
        PathPoint {
            x_m: f64::NAN,
            y_m: 0.0,
            speed_mps: 10.0,
            t_s: 0.0,
        },
        PathPoint {
            x_m: 10.0,
            y_m: 0.0,
            speed_mps: f64::INFINITY,
            t_s: 0.0,
        },
    ];
    for n in 0..500 {
        let kin = vehicle.kinematics(&world);
        let controls = match n % 4 {
            0 => Controls {
                steer_rad: f64::NAN,
                drive_torque_nm: [f64::NAN, f64::INFINITY, -5.0, 1e12],
                brake_torque_nm: [f64::NEG_INFINITY, f64::NAN, 1e12, -1.0],
            },
            1 => tracker.update(&kin, &[], 0.002),
            2 => tracker.update(&kin, &nan_path, 0.002),
            _ => tracker.update(
                &Kinematics {
                    x_m: f64::NAN,
                    ..kin
                },
                &nan_path,
                f64::NAN,
            ),
        };
        vehicle.set_controls(controls);
        let applied = vehicle.controls();
        for i in 0..4 {
            assert!(applied.drive_torque_nm[i] >= 0.0 && applied.drive_torque_nm[i].is_finite());
            assert!(applied.drive_torque_nm[i] <= p.max_drive_torque_wheel_nm(i));
            assert!(applied.brake_torque_nm[i] >= 0.0);
            assert!(applied.brake_torque_nm[i] <= p.max_brake_torque_wheel_nm(i));
        }
        assert!(applied.steer_rad.abs() <= p.max_steer_rad);
        let mu = [f64::NAN, -1.0, 0.0, 1e9][n % 4];
        vehicle.apply_forces(&mut world, mu);
        assert!(vehicle.try_apply_forces(&mut world, mu).is_err());
        vehicle.apply_forces(&mut world, 0.8);
        world.step();
    }
    let kin = vehicle.kinematics(&world);
    let values = [
        kin.x_m,
        kin.y_m,
        kin.z_m,
        kin.yaw_rad,
        kin.speed_mps,
        kin.yaw_rate_radps,
    ];
    assert!(values.iter().all(|v| v.is_finite()), "{kin:?}");
}
