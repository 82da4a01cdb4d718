//! Projection into the lane frame (the planners' hot path later): one lane of the curved merge
//! road (300 m radius, ~750 vertices 1 m apart) and the road-level queries.
//!
//! `cargo bench -p mergesim-types --bench projection`
//!
//! Measured 2026-12-02 (`-- --warm-up-time 2 --measurement-time 6`, shared 2-core machine under
//! a load average of ~12, so upper bounds): 787 µs per 1000 projections (0.79 µs each), 70 µs
//! per 1000 `point(s, d)`, 3.9 ms per 1000 `signed_distance_to_edge_m` (projection onto both
//! lanes + nearest outer edge). A variant looking up the nearest segment and then every segment
//! within reach (`locate_within_distance`) measured 2.4 ms per 1000: the nearest-first iterator
//! stays.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mergesim_types::MergeRoad;
use mergesim_types::lanes::{LaneRoad, THROUGH_LANE_ID, curved_merge_spec};

/// Deterministic query points near the through lane: (s, d) spread over the lane.
fn queries(road: &LaneRoad) -> Vec<[f64; 2]> {
    let lane = road.lane(THROUGH_LANE_ID).expect("lane 1");
    let len = lane.length_m();
    (0..1000)
        .map(|k| {
            let s = len * ((k as f64 * 0.618_033_988_75) % 1.0);
            let d = ((k as f64 * 0.414_213_562_37) % 1.0 - 0.5) * 7.0;
            lane.point(s, d)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let road = LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), 300.0).expect("spec"))
        .expect("road");
    let lane = road.lane(THROUGH_LANE_ID).expect("lane 1");
    let pts = queries(&road);
    c.bench_function("project_1000_points_curved_lane", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for p in &pts {
                let fp = lane.project(black_box(*p));
                acc += fp.s_m + fp.d_m;
            }
            acc
        })
    });
    c.bench_function("point_from_frame_1000", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for k in 0..1000 {
                let p = lane.point(black_box(k as f64 * 0.7), black_box(1.0));
                acc += p[0];
            }
            acc
        })
    });
    c.bench_function("signed_distance_to_edge_1000_points", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for p in &pts {
                acc += road.signed_distance_to_edge_m(black_box(*p));
            }
            acc
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
