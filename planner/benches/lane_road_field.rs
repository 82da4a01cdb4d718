//! One evaluation of the road terms as the local path steps them (Eqs. 2–3 gradient plus the
//! moving target's pull of Eq. 1), today's straight-road field (`road_field.rs`,
//! `attractive_field.rs`) against the lane-frame field (`lane_road_field.rs`) at the same 64
//! points of the straight merge road; and the lane-frame field on the 300 m curved merge.
//!
//! `cargo bench -p planner --bench lane_road_field -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mergesim_types::lanes::{LaneRoad, THROUGH_LANE_ID, curved_merge_spec};
use mergesim_types::{MergeRoad, VehicleShape};
use planner::attractive_field::AttractiveField;
use planner::lane_road_field::{LaneRoadField, LaneRoadGeometry};
use planner::params::PlannerParams;
use planner::road_field::{RoadField, RoadFieldParams};

/// 64 points over the first 400 m, across both lanes (the taper included).
fn points(map: impl Fn(f64, f64) -> [f64; 2]) -> Vec<[f64; 2]> {
    (0..64)
        .map(|i| {
            let x = 6.25 * i as f64;
            let y = 0.9 + 5.2 * ((i * 37) % 64) as f64 / 64.0;
            map(x, y)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let p = PlannerParams::default();
    let half_width_m = 0.5 * VehicleShape::default().width_m;
    let road = MergeRoad::default();
    let today = RoadField {
        road: &road,
        lane_amplitude: p.lane_amplitude,
        lane_sigma_m: p.lane_sigma_m,
        edge_gain_m2: p.edge_gain_m2,
        edge_clamp_distance_m: p.edge_clamp_distance_m,
        half_width_m,
    };
    let lanes = road.lane_road().expect("valid road");
    let geometry = LaneRoadGeometry::new(&lanes);
    let field = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m);
    let target = lanes.lane(THROUGH_LANE_ID).expect("lane").centreline();
    // The moving target's pull through the prepared frame of the through lane, as the
    // planner's `PotentialField::moving_target_gradient` computes it.
    let through = lanes
        .lanes()
        .iter()
        .position(|l| l.id() == THROUGH_LANE_ID)
        .expect("lane");
    let pts = points(|x, y| [x, y]);
    let (gain, lookahead) = (p.attractive_gain_per_m2, p.target_lookahead_m);
    c.bench_function("road_terms_today_straight_64_points", |b| {
        b.iter(|| {
            let mut acc = [0.0, 0.0];
            for q in black_box(&pts) {
                let g = today.gradient(q[0], q[1]);
                let a = AttractiveField::moving_target_gradient(gain, lookahead);
                acc[0] += g[0] + a[0];
                acc[1] += g[1] + a[1];
            }
            acc
        })
    });
    c.bench_function("road_terms_lane_frame_straight_64_points", |b| {
        b.iter(|| {
            let mut acc = [0.0, 0.0];
            for q in black_box(&pts) {
                let g = field.gradient(q[0], q[1]);
                let j = geometry.jacobian(through, *q);
                let a = [
                    -gain * lookahead * j.grad_s[0],
                    -gain * lookahead * j.grad_s[1],
                ];
                acc[0] += g[0] + a[0];
                acc[1] += g[1] + a[1];
            }
            acc
        })
    });
    let curved = LaneRoad::new(&curved_merge_spec(&road, 300.0).expect("valid")).expect("valid");
    let curved_geometry = LaneRoadGeometry::new(&curved);
    let curved_field =
        LaneRoadField::new(&curved_geometry, &RoadFieldParams::from(&p), half_width_m);
    let curved_lane = curved.lane(THROUGH_LANE_ID).expect("lane");
    let curved_pts = points(|x, y| {
        curved_lane.point(
            x + 50.0,
            y - road.lane_center_y_m(mergesim_types::Lane::Upper),
        )
    });
    let curved_target = curved_lane.centreline();
    c.bench_function("road_terms_lane_frame_curved_64_points", |b| {
        b.iter(|| {
            let mut acc = [0.0, 0.0];
            for q in black_box(&curved_pts) {
                let g = curved_field.gradient(q[0], q[1]);
                let j = curved_geometry.jacobian(through, *q);
                let a = [
                    -gain * lookahead * j.grad_s[0],
                    -gain * lookahead * j.grad_s[1],
                ];
                acc[0] += g[0] + a[0];
                acc[1] += g[1] + a[1];
            }
            acc
        })
    });
    // Where the time goes: one projection onto a centreline, and the edge term alone.
    for (name, c_line, pts, f) in [
        ("straight", target, &pts, &field),
        ("curved", curved_target, &curved_pts, &curved_field),
    ] {
        c.bench_function(&format!("projection_{name}_64_points"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for q in black_box(pts) {
                    acc += c_line.project(*q).d_m;
                }
                acc
            })
        });
        c.bench_function(&format!("edge_gradient_{name}_64_points"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for q in black_box(pts) {
                    acc += f.edge_gradient(q[0], q[1])[1];
                }
                acc
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
