//! Spawning settled on the springs, statics, and physical contact with barriers and cars.

use mergesim_types::{Lane, MergeRoad};
use vehicles::{Controls, GRAVITY_MPS2, PhysicsWorld, Vehicle, VehicleParams, collision_groups};

fn step(world: &mut PhysicsWorld, vehicles: &mut [&mut Vehicle], mu: f64) {
    for v in vehicles.iter_mut() {
        v.apply_forces(world, mu);
    }
    world.step();
}

/// At rest the car stays where it was spawned, and its wheel loads obey the statics of a beam
/// on two supports: ΣFz = m g, front axle share = l_r / L.
#[test]
fn spawned_at_rest_is_settled_with_static_axle_loads() {
    for name in vehicles::PRESET_NAMES {
        let p = VehicleParams::preset(name).unwrap();
        let mut world = PhysicsWorld::new(0.002).unwrap();
        world.add_flat_ground(100.0);
        let mut car = Vehicle::spawn(&mut world, &p, 3.0, -2.0, 0.7, 0.0).unwrap();
        for _ in 0..500 {
            step(&mut world, &mut [&mut car], 0.8);
            let k = car.kinematics(&world);
            assert!((k.z_m - p.cog_height_m).abs() < 1e-3, "{name}: z {}", k.z_m);
            assert!(
                k.pitch_rad.abs() < 1e-3 && k.roll_rad.abs() < 1e-3,
                "{name}: {k:?}"
            );
        }
        let k = car.kinematics(&world);
        assert!(
            (k.x_m - 3.0).abs() < 1e-3 && (k.y_m + 2.0).abs() < 1e-3,
            "{name}: {k:?}"
        );
        assert!((k.yaw_rad - 0.7).abs() < 1e-4);
        let loads = car.wheel_telemetry().map(|w| w.normal_load_n);
        let total: f64 = loads.iter().sum();
        let weight = p.mass_kg * GRAVITY_MPS2;
        assert!(
            (total - weight).abs() < 0.005 * weight,
            "{name}: {total} vs {weight}"
        );
        let front_share = (loads[0] + loads[1]) / total;
        let expected = p.cog_to_rear_axle_m / p.wheelbase_m();
        assert!(
            (front_share - expected).abs() < 0.005,
            "{name}: {front_share} vs {expected}"
        );
        assert!(
            (loads[0] - loads[1]).abs() < 0.005 * loads[0],
            "left/right symmetric"
        );
    }
}

/// Spawned at speed the wheels roll at road speed and the car coasts (no resistance is
/// modelled, so the speed holds).
#[test]
fn spawned_at_speed_rolls_at_road_speed() {
    let p = VehicleParams::default();
    let mut world = PhysicsWorld::new(0.002).unwrap();
    world.add_flat_ground(500.0);
    let mut car = Vehicle::spawn(&mut world, &p, 0.0, 0.0, 0.0, 20.0).unwrap();
    for _ in 0..1000 {
        step(&mut world, &mut [&mut car], 0.8);
    }
    let k = car.kinematics(&world);
    assert!((k.speed_mps - 20.0).abs() < 0.05, "{k:?}");
    assert!(
        k.y_m.abs() < 1e-3 && k.yaw_rad.abs() < 1e-4,
        "straight: {k:?}"
    );
    for w in car.wheel_telemetry() {
        let rolling = w.spin_radps * p.wheel_radius_m;
        assert!((rolling - k.speed_mps).abs() < 0.005 * k.speed_mps, "{w:?}");
    }
}

/// Corners of the chassis box in world X/Y.
fn corners(car: &Vehicle, world: &PhysicsWorld) -> [[f64; 2]; 4] {
    let k = car.kinematics(world);
    let b = car.body_box();
    let (s, c) = k.yaw_rad.sin_cos();
    let mut out = [[0.0; 2]; 4];
    for (i, (sx, sy)) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
        .iter()
        .enumerate()
    {
        let lx = b.center_offset_m[0] + sx * b.half_extents_m[0];
        let ly = b.center_offset_m[1] + sy * b.half_extents_m[1];
        out[i] = [k.x_m + c * lx - s * ly, k.y_m + s * lx + c * ly];
    }
    out
}

/// A car steered into the road edge is stopped by the edge walls (lower and upper edge,
/// including the taper of the merge section).
#[test]
fn edge_barriers_stop_cars() {
    let road = MergeRoad::default();
    let p = VehicleParams::default();
    // (x, lane, yaw): from the far lane towards the straight lower edge, the taper, and the
    // upper edge.
    for (x0, lane, yaw) in [
        (20.0, Lane::Upper, -0.4),
        (185.0, Lane::Upper, -0.4),
        (60.0, Lane::Lower, 0.4),
    ] {
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let colliders = world.add_lane_road(&road.lane_road().unwrap());
        let mut car =
            Vehicle::spawn(&mut world, &p, x0, road.lane_center_y_m(lane), yaw, 12.0).unwrap();
        let mut touched_edge = false;
        for _ in 0..1500 {
            car.set_controls(Controls {
                steer_rad: 0.0,
                drive_torque_nm: [0.0, 0.0, 300.0, 300.0],
                brake_torque_nm: [0.0; 4],
            });
            step(&mut world, &mut [&mut car], 0.8);
            for corner in corners(&car, &world) {
                let lower = road.lower_edge_y_m(corner[0]);
                assert!(
                    corner[1] > lower - 0.1,
                    "through the lower edge at {corner:?}"
                );
                assert!(
                    corner[1] < road.y_upper_m() + 0.1,
                    "through the upper edge at {corner:?}"
                );
            }
            let edges = &colliders.barriers;
            touched_edge |= edges.iter().any(|&edge| {
                world
                    .narrow_phase()
                    .contact_pair(edge, car.collider_handle())
                    .is_some_and(|pair| pair.has_any_active_contact())
            });
        }
        assert!(touched_edge, "the car at x0 = {x0} never reached the wall");
        let groups = world.colliders()[car.collider_handle()].collision_groups();
        assert_eq!(groups, collision_groups::vehicle());
    }
}

/// A car driving into a stopped car collides with it instead of passing through.
#[test]
fn cars_collide_with_each_other() {
    let p = VehicleParams::default();
    let mut world = PhysicsWorld::new(0.002).unwrap();
    world.add_flat_ground(300.0);
    let mut front = Vehicle::spawn(&mut world, &p, 20.0, 0.0, 0.0, 0.0).unwrap();
    let mut rear = Vehicle::spawn(&mut world, &p, 0.0, 0.0, 0.0, 8.0).unwrap();
    let mut front_moved = false;
    for _ in 0..2000 {
        step(&mut world, &mut [&mut front, &mut rear], 0.8);
        let (a, b) = (front.kinematics(&world), rear.kinematics(&world));
        assert!(
            a.x_m - b.x_m > p.length_m - 0.05,
            "overlap: {} vs {}",
            a.x_m,
            b.x_m
        );
        front_moved |= a.speed_mps > 1.0;
    }
    assert!(front_moved, "the impact must push the front car");
}
