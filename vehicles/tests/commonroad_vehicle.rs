//! The CommonRoad models behind the vehicle-model seam (`vehicles::CommonRoadVehicle`): the
//! tracker's controls become CommonRoad's inputs as documented, the cars brake to the friction
//! limit and stop without reversing, steady cornering matches the references (ks: v·tan δ / L;
//! st: the linear single-track model), and the kinematic box follows the model.

use vehicles::commonroad_models::{CommonRoadInput, KsState, ks_step_rk4};
use vehicles::{
    CommonRoadIntegration, CommonRoadModel, CommonRoadModelState, CommonRoadVehicle, Controls,
    GRAVITY_MPS2, LinearSingleTrack, PhysicsWorld, VehicleModel, VehicleParams,
};

const DT_S: f64 = 0.002;

fn world() -> PhysicsWorld {
    let mut world = PhysicsWorld::new(DT_S).unwrap();
    world.add_flat_ground(2000.0);
    world
}

fn car(world: &mut PhysicsWorld, model: CommonRoadModel, speed_mps: f64) -> CommonRoadVehicle {
    let params = VehicleParams::preset("bmw_320i").unwrap();
    CommonRoadVehicle::spawn(
        world,
        model,
        &params,
        CommonRoadIntegration::default(),
        [0.0, 0.0, 0.0],
        speed_mps,
    )
    .unwrap()
}

fn step(world: &mut PhysicsWorld, car: &mut CommonRoadVehicle, controls: Controls, mu: f64) {
    car.set_controls(controls);
    car.advance(world, mu);
    world.step();
}

fn steer(steer_rad: f64) -> Controls {
    Controls {
        steer_rad,
        ..Controls::default()
    }
}

fn full_brake(params: &VehicleParams) -> Controls {
    let mut c = Controls::default();
    for (i, torque) in c.brake_torque_nm.iter_mut().enumerate() {
        *torque = params.max_brake_torque_wheel_nm(i);
    }
    c
}

#[test]
fn the_ks_car_integrates_the_documented_inputs_exactly() {
    let mut world = world();
    let mut car = car(&mut world, CommonRoadModel::Ks, 20.0);
    let params = car.params().clone();
    let CommonRoadModelState::Ks(mut expected) = car.state() else {
        panic!("a ks car has a ks state")
    };
    let p = *car.model_params();
    let mut controls = steer(0.003);
    controls.drive_torque_nm = [0.0, 0.0, 300.0, 300.0];
    for k in 0..200 {
        let delta = if k < 100 { 0.003 } else { -0.002 };
        controls.steer_rad = delta;
        // The adapter: the steering velocity that reaches the command in one step, and the
        // net wheel torque over R_w·m (rear-wheel drive: only the rear torques count).
        let input = CommonRoadInput {
            steering_velocity_radps: (delta - expected.steering_angle_rad) / DT_S,
            acceleration_mps2: 600.0 / (params.wheel_radius_m * params.mass_kg),
        };
        expected = ks_step_rk4(&expected, &input, &p, DT_S);
        step(&mut world, &mut car, controls, 1.0);
    }
    let CommonRoadModelState::Ks(got) = car.state() else {
        panic!("a ks car has a ks state")
    };
    assert_eq!(got, expected);
    // The CoG is l_r ahead of the rear axle, and the box is where the model is.
    let k = car.kinematics(&world);
    let lr = params.cog_to_rear_axle_m;
    assert!((k.x_m - (got.x_m + lr * got.yaw_rad.cos())).abs() < 1e-12);
    assert!((k.y_m - (got.y_m + lr * got.yaw_rad.sin())).abs() < 1e-12);
    let pose = car.body().pose_m(&world).unwrap();
    let offset = car.body_box().center_offset_m[0];
    assert!(
        (pose[0] - (k.x_m + offset * k.yaw_rad.cos())).abs() < 1e-3,
        "{pose:?} {k:?}"
    );
    assert!(
        (pose[1] - (k.y_m + offset * k.yaw_rad.sin())).abs() < 1e-3,
        "{pose:?} {k:?}"
    );
}

#[test]
fn steady_cornering_matches_the_references() {
    let speed_mps = 20.0;
    let delta_rad = 0.01;
    let params = VehicleParams::preset("bmw_320i").unwrap();
    let wheelbase_m = params.wheelbase_m();
    // 4 s of steady steering: the yaw rate settles.
    let settle = |model| {
        let mut world = world();
        let mut car = car(&mut world, model, speed_mps);
        for _ in 0..2000 {
            step(&mut world, &mut car, steer(delta_rad), 1.0);
        }
        car.kinematics(&world)
    };
    let ks = settle(CommonRoadModel::Ks);
    let expected = speed_mps * delta_rad.tan() / wheelbase_m;
    assert!(
        (ks.yaw_rate_radps - expected).abs() < 1e-9 * expected,
        "ks {} vs {expected}",
        ks.yaw_rate_radps
    );
    assert!((ks.accel_lat_mps2 - ks.vx_body_mps * expected).abs() < 1e-6);
    // st: the linear single-track model of the same car (a_y ≈ 1.2 m/s², well inside st's
    // linear range) within 0.5 %. It understeers, so its yaw rate is below the kinematic one.
    let st = settle(CommonRoadModel::St);
    let linear = LinearSingleTrack::from_params(&params);
    let reference = linear.steady_state_yaw_rate_radps(speed_mps, delta_rad);
    assert!(
        (st.yaw_rate_radps - reference).abs() < 5e-3 * reference,
        "st {} vs linear {reference}",
        st.yaw_rate_radps
    );
    // Tyre stiffness proportional to the axle load makes the car neutral-steering: the linear
    // model's yaw rate is the kinematic one (to 0.1 %), and st agrees with both.
    assert!((reference - expected).abs() < 1e-3 * expected);
    let beta = linear.steady_state_sideslip_rad(speed_mps, delta_rad);
    assert!(
        (st.sideslip_rad - beta).abs() < 0.02 * beta.abs(),
        "st β {} vs linear {beta}",
        st.sideslip_rad
    );
    // std: Magic-Formula tyres, linear at this load: close to the linear model too.
    let std = settle(CommonRoadModel::Std);
    assert!(
        (std.yaw_rate_radps - reference).abs() < 0.03 * reference,
        "std {} vs linear {reference}",
        std.yaw_rate_radps
    );
}

#[test]
fn full_braking_is_friction_limited_and_stops_without_reversing() {
    for (model, mu) in [
        (CommonRoadModel::Ks, 1.0),
        (CommonRoadModel::Ks, 0.4),
        (CommonRoadModel::St, 0.4),
    ] {
        let mut world = world();
        let mut car = car(&mut world, model, 20.0);
        let brake = full_brake(&car.params().clone());
        step(&mut world, &mut car, brake, mu);
        let decel = -car.kinematics(&world).accel_long_mps2;
        let limit = (mu * GRAVITY_MPS2).min(11.5);
        assert!(
            (decel - limit).abs() < 1e-6 * limit,
            "{model:?} μ {mu}: {decel} vs {limit}"
        );
        for _ in 0..5000 {
            step(&mut world, &mut car, brake, mu);
        }
        let k = car.kinematics(&world);
        assert_eq!(k.speed_mps, 0.0, "{model:?}: {k:?}");
        // The stopping distance of a constant deceleration from 20 m/s (spawned at x = 0).
        let distance_m = k.x_m;
        let expected_m = 20.0 * 20.0 / (2.0 * limit);
        assert!(
            (distance_m - expected_m).abs() < 0.05,
            "{model:?} μ {mu}: {distance_m} vs {expected_m}"
        );
    }
    // std: the Magic-Formula tyres limit the deceleration to μ·g; the car's ABS (on for every
    // preset) holds the wheels at the tyre's peak slip, so it brakes near μ·g, stops and does
    // not spin (CommonRoad's model alone locks the wheels and spins). Below about 0.3 m/s the
    // model blends into the kinematic one, whose deceleration is the input's: the peak is taken
    // above 1 m/s.
    let mut world = world();
    let mut car = car(&mut world, CommonRoadModel::Std, 20.0);
    let brake = full_brake(&car.params().clone());
    let mut peak = 0.0f64;
    for _ in 0..5000 {
        step(&mut world, &mut car, brake, 0.4);
        let k = car.kinematics(&world);
        if k.speed_mps > 1.0 {
            peak = peak.max(-k.accel_long_mps2);
        }
    }
    let k = car.kinematics(&world);
    assert!(peak < 0.4 * GRAVITY_MPS2 * 1.05, "std peak {peak}");
    assert!(peak > 0.4 * GRAVITY_MPS2 * 0.85, "std peak {peak}");
    assert_eq!(k.speed_mps, 0.0, "{k:?}");
    assert!(k.yaw_rad.abs() < 0.01, "std spun: {k:?}");
    let expected_m = 20.0 * 20.0 / (2.0 * 0.4 * GRAVITY_MPS2);
    assert!(
        k.x_m > expected_m && k.x_m < 1.2 * expected_m,
        "std stops in {} m, μ·g would take {expected_m} m",
        k.x_m
    );
}

#[test]
fn the_models_are_named_and_refuse_bad_spawns() {
    for model in CommonRoadModel::ALL {
        assert_eq!(CommonRoadModel::from_name(model.name()), Some(model));
    }
    assert_eq!(CommonRoadModel::from_name("rapier"), None);
    let params = VehicleParams::preset("bmw_320i").unwrap();
    let mut world = world();
    let spawn = |world: &mut PhysicsWorld, pose: [f64; 3], v: f64, i: CommonRoadIntegration| {
        CommonRoadVehicle::spawn(world, CommonRoadModel::St, &params, i, pose, v)
    };
    let ok = CommonRoadIntegration::default();
    assert!(spawn(&mut world, [f64::NAN, 0.0, 0.0], 10.0, ok).is_err());
    assert!(spawn(&mut world, [0.0, 0.0, 0.0], -1.0, ok).is_err());
    assert!(
        spawn(&mut world, [5000.0, 0.0, 0.0], 10.0, ok).is_err(),
        "off the ground"
    );
    let bad = CommonRoadIntegration {
        st_max_substep_s: 0.0,
        ..ok
    };
    let e = spawn(&mut world, [0.0, 0.0, 0.0], 10.0, bad).err().unwrap();
    assert!(e.to_string().contains("st_max_substep_s"), "{e}");
}

#[test]
fn a_ks_state_does_not_depend_on_the_kinematic_box() {
    // Two worlds, one with a wall in the way: the model is not pushed by contacts.
    let run = |extra_box: bool| {
        let mut world = world();
        if extra_box {
            vehicles::KinematicBox::spawn(&mut world, 2.0, 10.0, 0.0, 2.0, [30.0, 0.0, 0.0])
                .unwrap();
        }
        let mut car = car(&mut world, CommonRoadModel::Ks, 20.0);
        for _ in 0..1000 {
            step(&mut world, &mut car, steer(0.0), 1.0);
        }
        car.state()
    };
    assert_eq!(run(false), run(true));
    let CommonRoadModelState::Ks(KsState { x_m, .. }) = run(false) else {
        panic!("ks")
    };
    assert!((x_m - (40.0 - 1.4227170936)).abs() < 1e-9, "{x_m}");
}
