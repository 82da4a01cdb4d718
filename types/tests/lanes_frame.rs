//! Roads made of lanes, the lane frame: (s, d) round trips, heading and curvature on arcs,
//! cleaning and smoothing, invariance under rotation and translation, precision far from the
//! origin.

use std::f64::consts::PI;

use mergesim_types::MergeRoad;
use mergesim_types::lanes::{
    Centreline, ENDING_LANE_ID, LaneId, LaneRoad, LaneRoadSpec, LaneTolerances, THROUGH_LANE_ID,
    curved_merge_spec,
};

const R: f64 = 300.0;

fn curved() -> LaneRoad {
    LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), R).unwrap()).unwrap()
}

/// Points of a circular arc about `c`, radius `r`, from angle `a0` over `sweep` (rad), chords of
/// at most `step` (m).
fn arc(c: [f64; 2], r: f64, a0: f64, sweep: f64, step: f64) -> Vec<[f64; 2]> {
    let n = ((r * sweep.abs()) / step).ceil() as usize;
    (0..=n)
        .map(|k| {
            let a = a0 + sweep * k as f64 / n as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[test]
fn projection_round_trips_on_curved_lanes() {
    let road = curved();
    let mut worst_sd: f64 = 0.0;
    let mut worst_p: f64 = 0.0;
    for id in [THROUGH_LANE_ID, ENDING_LANE_ID] {
        let lane = road.lane(id).unwrap();
        let len = lane.length_m();
        for i in 0..=400 {
            // s from 10 m before the start to 10 m after the end, off the vertices.
            let s = -10.0 + (len + 20.0) * (i as f64 + 0.37) / 401.0;
            for d in [-3.5, -1.75, -0.3, 0.0, 0.9, 1.75, 3.5] {
                let p = lane.point(s, d);
                let fp = lane.project(p);
                worst_sd = worst_sd.max((fp.s_m - s).abs()).max((fp.d_m - d).abs());
                // And point → (s, d) → point.
                let q = [p[0] + 0.123 * d, p[1] - 0.077 * s / len];
                let back = lane.point(lane.project(q).s_m, lane.project(q).d_m);
                worst_p = worst_p.max(dist(back, q));
            }
        }
    }
    // Scale: coordinates up to ~600 m; 1e-9 · 1 m is far below that.
    assert!(worst_sd < 1e-9, "(s, d) round trip error {worst_sd:e} m");
    assert!(worst_p < 1e-9, "point round trip error {worst_p:e} m");
}

#[test]
fn arc_heading_and_curvature_match_the_circle() {
    let road = curved();
    let centre = [0.0, MergeRoad::default().y_lane_m() + R];
    let w = MergeRoad::default().lane_width_m;
    for (id, radius) in [
        (THROUGH_LANE_ID, R - 0.5 * w),
        (ENDING_LANE_ID, R + 0.5 * w),
    ] {
        let lane = road.lane(id).unwrap();
        let mut worst_k: f64 = 0.0;
        let mut worst_h: f64 = 0.0;
        for i in 0..2000 {
            let s = lane.length_m() * (i as f64 + 0.5) / 2000.0;
            let (h, k) = lane.centreline().heading_and_curvature(s);
            worst_k = worst_k.max((k * radius - 1.0).abs());
            // The circle's tangent at the point's angle about the centre (left turn: +π/2).
            let p = lane.point(s, 0.0);
            let tangent = (p[1] - centre[1]).atan2(p[0] - centre[0]) + 0.5 * PI;
            let dh = ((h - tangent + PI).rem_euclid(2.0 * PI) - PI).abs();
            worst_h = worst_h.max(dh);
        }
        // Stated bound (module docs): relative c²/(4R²) = 2.8e-6 for c = 1 m, R ≈ 300 m.
        assert!(
            worst_k < 1e-5,
            "lane {id}: relative curvature error {worst_k:e}"
        );
        assert!(worst_h < 1e-6, "lane {id}: heading error {worst_h:e} rad");
    }
}

#[test]
fn frame_axes_match_finite_differences() {
    let road = curved();
    let lane = road.lane(THROUGH_LANE_ID).unwrap();
    let h = 1e-5;
    for (s, d) in [(10.3, 1.2), (250.55, -2.0), (600.01, 0.4)] {
        let ax = lane.centreline().axes(s, d);
        let ps = [lane.point(s + h, d), lane.point(s - h, d)];
        let pd = [lane.point(s, d + h), lane.point(s, d - h)];
        for i in 0..2 {
            assert!((ax.dp_ds[i] - (ps[0][i] - ps[1][i]) / (2.0 * h)).abs() < 1e-6);
            assert!((ax.dp_dd[i] - (pd[0][i] - pd[1][i]) / (2.0 * h)).abs() < 1e-6);
        }
    }
}

#[test]
fn duplicate_vertex_centreline_is_cleaned_without_jumps() {
    let radius = 150.0;
    let clean = arc([0.0, radius], radius, -0.5 * PI, 0.6, 1.0);
    let mut raw = Vec::new();
    for (i, p) in clean.iter().enumerate() {
        raw.push(*p);
        if i % 7 == 3 {
            raw.push(*p); // exact duplicate
        }
        if i % 11 == 5 && i + 1 < clean.len() {
            raw.push([p[0] + 1e-3, p[1] + 5e-4]); // near-duplicate (1.1 mm)
        }
    }
    assert!(raw.len() > clean.len() + 10);
    let c = Centreline::new(
        LaneId(1),
        &raw,
        LaneTolerances::default().vertex_merge_m,
        0.0,
    )
    .unwrap();
    assert_eq!(c.vertex_count(), clean.len());
    // Without cleaning (tolerance 0: only exact duplicates go), the near-duplicates remain and
    // the curvature spikes at them.
    let noisy = Centreline::new(LaneId(1), &raw, 0.0, 0.0).unwrap();
    assert!(noisy.vertex_count() > clean.len());
    let spike = noisy
        .vertex_s_m()
        .iter()
        .map(|&s| noisy.curvature_1pm(s).abs())
        .fold(0.0, f64::max);
    assert!(spike * radius > 10.0, "raw curvature spike {spike}");
    // Cleaned: heading and curvature continuous at every vertex, curvature = 1/R.
    let eps = 1e-7;
    for &s in &c.vertex_s_m()[1..c.vertex_count() - 1] {
        let jump_h = (c.heading_rad(s + eps) - c.heading_rad(s - eps)).abs();
        let jump_k = (c.curvature_1pm(s + eps) - c.curvature_1pm(s - eps)).abs();
        assert!(jump_h < 1e-8, "heading jump {jump_h:e} rad at s = {s}");
        assert!(
            jump_k * radius < 1e-6,
            "curvature jump {jump_k:e} 1/m at s = {s}"
        );
        assert!((c.curvature_1pm(s) * radius - 1.0).abs() < 1e-9);
    }
}

#[test]
fn smoothing_window_keeps_a_circle_and_tames_noise() {
    let radius = 200.0;
    let clean = arc([0.0, radius], radius, -0.5 * PI, 0.5, 1.0);
    // Lateral noise of ±2 cm alternating at the vertices.
    let noisy: Vec<[f64; 2]> = clean
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let r = [p[0], p[1] - radius];
            let k = 1.0 + sign * 0.02 / radius;
            [r[0] * k, r[1] * k + radius]
        })
        .collect();
    let raw = Centreline::new(LaneId(1), &noisy, 0.05, 0.0).unwrap();
    let smooth = Centreline::new(LaneId(1), &noisy, 0.05, 5.0).unwrap();
    let mid = 0.5 * raw.length_m();
    let err = |c: &Centreline| {
        (mid - 20.0..mid + 20.0)
            .step_by_f(0.25)
            .into_iter()
            .map(|s| (c.curvature_1pm(s) * radius - 1.0).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        err(&raw) > 5.0,
        "noise visible without smoothing: {}",
        err(&raw)
    );
    assert!(
        err(&smooth) < 0.1 * err(&raw),
        "{} vs {}",
        err(&smooth),
        err(&raw)
    );
    // On the clean arc the window changes nothing beyond rounding.
    let a = Centreline::new(LaneId(1), &clean, 0.05, 0.0).unwrap();
    let b = Centreline::new(LaneId(1), &clean, 0.05, 5.0).unwrap();
    for i in 0..100 {
        let s = a.length_m() * i as f64 / 99.0;
        assert!((a.curvature_1pm(s) - b.curvature_1pm(s)).abs() < 1e-9);
        assert!((a.heading_rad(s) - b.heading_rad(s)).abs() < 1e-9);
    }
}

trait StepBy {
    fn step_by_f(self, step: f64) -> Vec<f64>;
}
impl StepBy for std::ops::Range<f64> {
    fn step_by_f(self, step: f64) -> Vec<f64> {
        let n = ((self.end - self.start) / step) as usize;
        (0..n).map(|k| self.start + step * k as f64).collect()
    }
}

fn transform(spec: &LaneRoadSpec, angle: f64, shift: [f64; 2]) -> LaneRoadSpec {
    let (sn, cs) = angle.sin_cos();
    let mut out = spec.clone();
    for l in &mut out.lanes {
        for p in &mut l.centreline_m {
            *p = [
                cs * p[0] - sn * p[1] + shift[0],
                sn * p[0] + cs * p[1] + shift[1],
            ];
        }
    }
    out
}

#[test]
fn rotated_and_shifted_road_projects_the_same() {
    let spec = curved_merge_spec(&MergeRoad::default(), R).unwrap();
    let (angle, shift) = (2.1, [5900.0, -3100.0]);
    let a = LaneRoad::new(&spec).unwrap();
    let b = LaneRoad::new(&transform(&spec, angle, shift)).unwrap();
    let (sn, cs) = angle.sin_cos();
    let mut worst: f64 = 0.0;
    for id in [THROUGH_LANE_ID, ENDING_LANE_ID] {
        let (la, lb) = (a.lane(id).unwrap(), b.lane(id).unwrap());
        for i in 0..500 {
            let p = la.point(
                la.length_m() * (i as f64 + 0.5) / 500.0,
                3.0 * ((i % 13) as f64 / 6.0 - 1.0),
            );
            let q = [
                cs * p[0] - sn * p[1] + shift[0],
                sn * p[0] + cs * p[1] + shift[1],
            ];
            let (fa, fb) = (la.project(p), lb.project(q));
            worst = worst
                .max((fa.s_m - fb.s_m).abs())
                .max((fa.d_m - fb.d_m).abs());
            assert!((la.curvature_1pm(fa.s_m) - lb.curvature_1pm(fb.s_m)).abs() < 1e-9);
            assert_eq!(a.is_drivable(p), b.is_drivable(q));
        }
    }
    assert!(worst < 1e-9, "(s, d) differ by {worst:e} m");
}

#[test]
fn far_from_origin_projects_as_accurately() {
    let spec = curved_merge_spec(&MergeRoad::default(), R).unwrap();
    let shift = [5900.0, 5900.0];
    let near = LaneRoad::new(&spec).unwrap();
    let far = LaneRoad::new(&transform(&spec, 0.0, shift)).unwrap();
    let round_trip = |road: &LaneRoad| {
        let lane = road.lane(THROUGH_LANE_ID).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..1000 {
            let s = lane.length_m() * (i as f64 + 0.5) / 1000.0;
            let d = 3.0 * ((i % 17) as f64 / 8.0 - 1.0);
            let fp = lane.project(lane.point(s, d));
            worst = worst.max((fp.s_m - s).abs()).max((fp.d_m - d).abs());
        }
        worst
    };
    let (e_near, e_far) = (round_trip(&near), round_trip(&far));
    assert!(
        e_near < 1e-9 && e_far < 1e-9,
        "near {e_near:e}, far {e_far:e}"
    );
    let m = MergeRoad::default();
    let p = [200.0, m.y_lane_m() + 0.3];
    let q = [p[0] + shift[0], p[1] + shift[1]];
    let (dn, df) = (
        near.signed_distance_to_edge_m(p),
        far.signed_distance_to_edge_m(q),
    );
    assert!((dn - df).abs() < 1e-9, "{dn} vs {df}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// Arcs of any radius, sampling, orientation and place: (s, d) round trips, and the
    /// curvature within the stated bound c²/(16R²) (plus higher orders: factor 1.05, and the
    /// input's rounding).
    #[test]
    fn random_arcs_round_trip(
        radius in 50.0f64..3000.0,
        sweep in 0.05f64..1.5,
        step in 0.3f64..5.0,
        start_angle in -PI..PI,
        left in proptest::bool::ANY,
        shift_x in -10_000.0f64..10_000.0,
        shift_y in -10_000.0f64..10_000.0,
        u in 0.0f64..1.0,
        v in -1.0f64..1.0,
    ) {
        let sweep = if left { sweep } else { -sweep };
        // At least two chords: one chord is a straight segment, which carries no curvature
        // for the bound to hold (a 2.5 m arc sampled every 4.6 m was once drawn).
        let step = step.min(0.5 * radius * sweep.abs());
        let pts = arc([shift_x, shift_y], radius, start_angle, sweep, step);
        let chord = dist(pts[0], pts[1]);
        let lane = Centreline::new(LaneId(1), &pts, 0.05, 0.0).unwrap();
        let s = lane.length_m() * u;
        let d = v * (0.25 * radius).min(10.0);
        let p = lane.point(s, d);
        let fp = lane.project(p);
        proptest::prop_assert!((fp.s_m - s).abs() < 1e-9 && (fp.d_m - d).abs() < 1e-9,
            "({}, {}) vs ({s}, {d})", fp.s_m, fp.d_m);
        let k = lane.curvature_1pm(s) * radius * sweep.signum();
        // Plus the input's own rounding: vertices carry an ulp of their coordinates (δ), which
        // the chord-to-chord turn (≈ c/R) feels as a relative error of order 2δ·R/c².
        let coord = shift_x.abs().max(shift_y.abs()) + radius;
        let rounding = 4.0 * f64::EPSILON * coord * radius / (chord * chord);
        let bound = 1.05 * chord * chord / (16.0 * radius * radius) + rounding;
        proptest::prop_assert!((k - 1.0).abs() <= bound, "relative error {} > {bound}", (k - 1.0).abs());
    }
}
