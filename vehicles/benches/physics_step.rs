//! Cost of one physics step per vehicle at dt = 2 ms: 10 cars on the merge road.
//!
//! `cargo bench -p vehicles --bench physics_step -- --warm-up-time 1 --measurement-time 5`
//!
//! - `step_10_vehicles`: `apply_forces` (4 ray casts, suspension, tyres, wheel spin) for 10 cars
//!   plus one rapier step; divide by 10 for the per-vehicle figure (criterion prints the
//!   element throughput).
//! - `rapier_step_only_10_vehicles`: the rapier step alone with the same bodies (forces kept
//!   from the last `apply_forces`), to separate rapier's share from the vehicle model's.
//! - `tracker_update`: one pure-pursuit + PID update on a 20-point path.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mergesim_types::{Lane, MergeRoad, PathPoint};
use vehicles::tracker::{Tracker, TrackerParams};
use vehicles::{PhysicsWorld, Vehicle, VehicleParams};

const DT_S: f64 = 0.002;
const VEHICLES: usize = 10;
/// Steps before the scene is rebuilt (4 s: the lower-lane cars stay before the taper).
const STEPS_PER_SCENE: u64 = 2000;

fn scene() -> (PhysicsWorld, Vec<Vehicle>) {
    let road = MergeRoad::default();
    let mut world = PhysicsWorld::new(DT_S).expect("valid dt");
    world.add_lane_road(&road.lane_road().expect("the default road is valid"));
    let params = VehicleParams::default();
    let mut cars = Vec::with_capacity(VEHICLES);
    for i in 0..VEHICLES / 2 {
        let offset = 30.0 * i as f64;
        for (lane, x) in [(Lane::Lower, -40.0 + offset), (Lane::Upper, -25.0 + offset)] {
            let y = road.lane_center_y_m(lane);
            cars.push(Vehicle::spawn(&mut world, &params, x, y, 0.0, 20.0).expect("spawn"));
        }
    }
    (world, cars)
}

fn bench_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("physics_step");
    group.throughput(Throughput::Elements(VEHICLES as u64));
    group.bench_function("step_10_vehicles", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut done = 0;
            while done < iters {
                let (mut world, mut cars) = scene();
                let n = (iters - done).min(STEPS_PER_SCENE);
                let start = Instant::now();
                for _ in 0..n {
                    for car in &mut cars {
                        car.apply_forces(&mut world, 0.8);
                    }
                    world.step();
                }
                total += start.elapsed();
                black_box(cars[0].kinematics(&world));
                done += n;
            }
            total
        })
    });
    group.bench_function("rapier_step_only_10_vehicles", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut done = 0;
            while done < iters {
                let (mut world, mut cars) = scene();
                for car in &mut cars {
                    car.apply_forces(&mut world, 0.8);
                }
                let n = (iters - done).min(STEPS_PER_SCENE / 4);
                let start = Instant::now();
                for _ in 0..n {
                    world.step();
                }
                total += start.elapsed();
                black_box(cars[0].kinematics(&world));
                done += n;
            }
            total
        })
    });
    group.finish();

    let params = VehicleParams::default();
    let path: Vec<PathPoint> = (0..20)
        .map(|i| PathPoint {
            x_m: 2.0 * i as f64,
            y_m: 0.05 * i as f64,
            speed_mps: 20.0 - 0.1 * i as f64,
            t_s: 0.1 * i as f64,
        })
        .collect();
    let (world, cars) = scene();
    let kin = cars[0].kinematics(&world);
    let mut tracker = Tracker::new(TrackerParams::default(), &params);
    c.bench_function("tracker_update", |b| {
        b.iter(|| black_box(tracker.update(black_box(&kin), black_box(&path), DT_S)))
    });
}

criterion_group!(benches, bench_step);
criterion_main!(benches);
