//! The road terms in the lane frame (`lane_road_field.rs`): the same field as today's on the
//! straight merge road, finite-difference gradients on curved roads, the same field on a
//! rotated and shifted copy, and an ending lane closed by an edge.

use mergesim_types::lanes::{
    ENDING_LANE_ID, LaneRoad, LaneRoadSpec, OnRampParams, THROUGH_LANE_ID, curved_merge_spec,
    on_ramp_ids, on_ramp_spec,
};
use mergesim_types::{MergeRoad, VehicleShape};
use planner::attractive_field::{AttractionParams, AttractiveField};
use planner::lane_frame::lane_relative_heading_rad;
use planner::lane_road_field::{LaneAttraction, LaneRoadField, LaneRoadGeometry};
use planner::params::PlannerParams;
use planner::road_field::{RoadField, RoadFieldParams};

fn half_width_m() -> f64 {
    0.5 * VehicleShape::default().width_m
}

fn today<'a>(road: &'a MergeRoad, p: &PlannerParams) -> RoadField<'a> {
    RoadField {
        road,
        lane_amplitude: p.lane_amplitude,
        lane_sigma_m: p.lane_sigma_m,
        edge_gain_m2: p.edge_gain_m2,
        edge_clamp_distance_m: p.edge_clamp_distance_m,
        half_width_m: half_width_m(),
    }
}

/// Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, top 53 bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Where the Euclidean distance to the lower edge can differ from today's Y − Y_l(X): the
/// taper, and the band beside its first vertex where the taper segment is nearer than the
/// flat one (x ≥ 160 − k·|y|/2 for k = 0.035; 1 m covers it for |y| < 57 m).
fn in_taper_zone(road: &MergeRoad, x: f64) -> bool {
    x > road.merge_start_x_m - 1.0 && x < road.merge_end_x_m
}

#[test]
fn straight_road_gives_todays_field() {
    let road = MergeRoad::default();
    let lanes = road.lane_road().unwrap();
    let geometry = LaneRoadGeometry::new(&lanes);
    assert_eq!(
        geometry.edge_count(),
        2,
        "upper edge, lower edge with taper"
    );
    assert_eq!(geometry.divider_count(), 1);
    let p = PlannerParams::default();
    let old = today(&road, &p);
    let new = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m());
    let (mut n_equal, mut n_taper) = (0, 0);
    let (mut max_lane, mut max_edge, mut max_grad) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut taper_value_rel, mut taper_grad_rel) = (0.0_f64, 0.0_f64);
    let mut taper_distance_rel = 0.0_f64;
    let cos_theta = 1.0 / road.taper_slope().hypot(1.0);
    // Which edge is the lower one: 1 m above it, 6 m below the upper edge.
    let lower = geometry
        .edge_distances_m(0.0, 1.0)
        .iter()
        .position(|d| (d - 1.0).abs() < 1e-12)
        .unwrap();
    // x from before the road's start to past its end; y from below the lower edge to above the
    // upper one (on and beyond the edges, the clamped continuation).
    for i in 0..=240 {
        let x = -80.0 + 3.55 * i as f64;
        for jy in 0..=50 {
            let y = -1.5 + 0.2 * jy as f64 + 0.013;
            let lv = (new.lane_value(x, y), old.lane_value(x, y));
            let lg = (new.lane_gradient(x, y), old.lane_gradient(x, y));
            max_lane = max_lane.max((lv.0 - lv.1).abs());
            for k in 0..2 {
                max_lane = max_lane.max((lg.0[k] - lg.1[k]).abs());
            }
            assert!(close(lv.0, lv.1, 1e-12), "divider ({x}, {y}): {lv:?}");
            let ev = (new.edge_value(x, y), old.edge_value(x, y));
            let eg = (new.edge_gradient(x, y), old.edge_gradient(x, y));
            let rel = |a: f64, b: f64| (a - b).abs() / (1.0 + a.abs().max(b.abs()));
            if in_taper_zone(&road, x) {
                n_taper += 1;
                // The lower edge is the graph of Y_l(X), slopes in [0, k]: the Euclidean distance
                // lies between the vertical one and the vertical one · cos θ, θ = atan k.
                let delta_today = y - road.lower_edge_y_m(x);
                let delta = geometry.edge_distances_m(x, y)[lower];
                let delta_min = delta_today * cos_theta;
                assert!(
                    delta.abs() <= delta_today.abs() + 1e-12
                        && delta.abs() >= delta_min.abs() - 1e-12
                        && delta * delta_today >= 0.0,
                    "({x}, {y}): {delta} vs {delta_today}"
                );
                taper_distance_rel =
                    taper_distance_rel.max((delta - delta_today).abs() / delta_today.abs());
                // So the edge term lies between today's and the one with the lower clearance
                // shrunk by cos θ (e is decreasing).
                let e = |g: f64| {
                    let (gain, clamp) = (p.edge_gain_m2, p.edge_clamp_distance_m);
                    if g >= clamp {
                        0.5 * gain / (g * g)
                    } else {
                        0.5 * gain / (clamp * clamp) - gain / clamp.powi(3) * (g - clamp)
                    }
                };
                let upper = e(road.y_upper_m() - y - half_width_m());
                let shrunk = upper + e(delta_min - half_width_m());
                let (lo, hi) = (ev.1.min(shrunk), ev.1.max(shrunk));
                assert!(
                    ev.0 >= lo * (1.0 - 1e-12) && ev.0 <= hi * (1.0 + 1e-12),
                    "({x}, {y}): {} not in [{lo}, {hi}]",
                    ev.0
                );
                taper_value_rel = taper_value_rel.max((ev.0 - ev.1).abs() / ev.1.abs());
                let norm = eg.1[0].hypot(eg.1[1]);
                taper_grad_rel =
                    taper_grad_rel.max((eg.0[0] - eg.1[0]).hypot(eg.0[1] - eg.1[1]) / norm);
                continue;
            }
            n_equal += 1;
            max_edge = max_edge.max(rel(ev.0, ev.1));
            for k in 0..2 {
                max_grad = max_grad.max(rel(eg.0[k], eg.1[k]));
            }
            assert!(close(ev.0, ev.1, 1e-9), "edge ({x}, {y}): {ev:?}");
            for k in 0..2 {
                assert!(close(eg.0[k], eg.1[k], 1e-9), "edge ∇ ({x}, {y}): {eg:?}");
            }
        }
    }
    eprintln!(
        "straight road: {n_equal} points compared outside the taper: max |Δ| divider (value and \
         gradient) {max_lane:.1e}, max relative Δ edge value {max_edge:.1e}, edge gradient \
         {max_grad:.1e}; {n_taper} points in the taper zone: max relative Δ lower-edge distance \
         {taper_distance_rel:.2e} (1 − cos θ = {:.2e}), edge value {taper_value_rel:.2e}, edge \
         gradient {taper_grad_rel:.2e}",
        1.0 - cos_theta
    );
    assert!(n_equal > 10_000 && n_taper > 1000);
    // The distances do differ in the taper (else this test would not see the taper).
    assert!(taper_distance_rel > 0.5 * (1.0 - cos_theta));
}

#[test]
fn straight_road_attraction_is_todays() {
    let road = MergeRoad::default();
    let lanes = road.lane_road().unwrap();
    let p = PlannerParams::default();
    let (ego_x, ego_y) = (150.0, 1.75);
    let old = AttractiveField {
        gain_per_m2: p.attractive_gain_per_m2,
        target_x_m: ego_x + p.target_lookahead_m,
    };
    let old_pull =
        AttractiveField::moving_target_gradient(p.attractive_gain_per_m2, p.target_lookahead_m);
    for id in [THROUGH_LANE_ID, ENDING_LANE_ID] {
        let lane = lanes.lane(id).unwrap();
        let new = LaneAttraction::ahead_of(lane, &AttractionParams::from(&p), ego_x, ego_y);
        for (x, y) in [
            (150.0, 1.75),
            (0.0, 5.25),
            (171.3, 2.9),
            (400.0, 4.0),
            (-70.0, 0.5),
        ] {
            assert!(
                close(new.value(x, y), old.value(x), 1e-12),
                "{id:?} ({x}, {y})"
            );
            let (g, go) = (new.gradient(x, y), old.gradient(x));
            assert!(
                close(g[0], go[0], 1e-12) && g[1].abs() < 1e-15,
                "{g:?} vs {go:?}"
            );
            let pull = LaneAttraction::moving_target_gradient(
                lane.centreline(),
                p.attractive_gain_per_m2,
                p.target_lookahead_m,
                x,
                y,
            );
            assert_eq!(pull, old_pull);
        }
    }
}

fn curved_merge() -> LaneRoad {
    LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), 300.0).unwrap()).unwrap()
}

fn on_ramp(taper_length_m: f64) -> LaneRoad {
    let params = OnRampParams {
        taper_length_m,
        ..OnRampParams::default()
    };
    LaneRoad::new(&on_ramp_spec(&params).unwrap()).unwrap()
}

/// Central differences of the field's value against its gradient at `n` points drawn by
/// `sample`; returns the largest relative error.
fn check_gradients(road: &LaneRoad, n: usize, mut sample: impl FnMut(&mut Lcg) -> [f64; 2]) -> f64 {
    let geometry = LaneRoadGeometry::new(road);
    let p = PlannerParams::default();
    let field = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m());
    let mut rng = Lcg(21);
    let h = 1e-6;
    let mut worst = 0.0_f64;
    for _ in 0..n {
        let [x, y] = sample(&mut rng);
        let g = field.gradient(x, y);
        let fd = [
            (field.value(x + h, y) - field.value(x - h, y)) / (2.0 * h),
            (field.value(x, y + h) - field.value(x, y - h)) / (2.0 * h),
        ];
        for k in 0..2 {
            let err = (g[k] - fd[k]).abs() / (1.0 + fd[k].abs());
            worst = worst.max(err);
            assert!(
                err < 1e-6,
                "({x}, {y}) component {k}: analytic {g:?}, numeric {fd:?}"
            );
        }
        // The attraction along the through lane (lane 1 on both roads).
        let lane = road.lane(THROUGH_LANE_ID).unwrap();
        let a = LaneAttraction::ahead_of(lane, &AttractionParams::from(&p), x - 30.0, y);
        let ga = a.gradient(x, y);
        let fda = [
            (a.value(x + h, y) - a.value(x - h, y)) / (2.0 * h),
            (a.value(x, y + h) - a.value(x, y - h)) / (2.0 * h),
        ];
        for k in 0..2 {
            let err = (ga[k] - fda[k]).abs() / (1.0 + fda[k].abs());
            worst = worst.max(err);
            assert!(err < 1e-6, "attraction ({x}, {y}): {ga:?} vs {fda:?}");
        }
    }
    worst
}

#[test]
fn gradients_match_finite_differences_on_the_curved_merge() {
    let road = curved_merge();
    let through = road.lane(THROUGH_LANE_ID).unwrap();
    // Points across both lanes and a metre beyond either edge, along the whole curve.
    let worst = check_gradients(&road, 3000, |r| {
        let s = -40.0 + 780.0 * r.next();
        let d = -6.0 + 10.5 * r.next();
        through.point(s, d)
    });
    eprintln!("curved merge: worst relative gradient error {worst:.1e}");
}

#[test]
fn gradients_match_finite_differences_on_the_on_ramp() {
    let road = on_ramp(50.0);
    let ramp = road.lane(on_ramp_ids::RAMP).unwrap();
    let ramp_len = ramp.length_m();
    let worst = check_gradients(&road, 3000, |r| {
        if r.next() < 0.3 {
            // On and beside the ramp's arc.
            ramp.point(ramp_len * r.next(), -2.5 + 5.0 * r.next())
        } else {
            [650.0 * r.next(), -5.5 + 13.0 * r.next()]
        }
    });
    eprintln!("on-ramp: worst relative gradient error {worst:.1e}");
}

fn rotate_shift(p: [f64; 2], angle: f64, shift: [f64; 2]) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [
        c * p[0] - s * p[1] + shift[0],
        s * p[0] + c * p[1] + shift[1],
    ]
}

#[test]
fn rotated_and_shifted_road_gives_the_same_field() {
    let spec = curved_merge_spec(&MergeRoad::default(), 300.0).unwrap();
    let (angle, shift) = (2.2, [1234.5, -987.6]);
    let moved = LaneRoadSpec {
        lanes: spec
            .lanes
            .iter()
            .map(|l| {
                let mut l = l.clone();
                l.centreline_m = l
                    .centreline_m
                    .iter()
                    .map(|&p| rotate_shift(p, angle, shift))
                    .collect();
                l
            })
            .collect(),
        tolerances: spec.tolerances.clone(),
    };
    let (a, b) = (
        LaneRoad::new(&spec).unwrap(),
        LaneRoad::new(&moved).unwrap(),
    );
    let (ga, gb) = (LaneRoadGeometry::new(&a), LaneRoadGeometry::new(&b));
    assert_eq!(ga.edge_count(), gb.edge_count());
    let p = PlannerParams::default();
    let (fa, fb) = (
        LaneRoadField::new(&ga, &RoadFieldParams::from(&p), half_width_m()),
        LaneRoadField::new(&gb, &RoadFieldParams::from(&p), half_width_m()),
    );
    let through = a.lane(THROUGH_LANE_ID).unwrap();
    let mut rng = Lcg(7);
    let mut worst = 0.0_f64;
    for _ in 0..2000 {
        let q = through.point(-40.0 + 780.0 * rng.next(), -6.0 + 10.5 * rng.next());
        let qm = rotate_shift(q, angle, shift);
        let (va, vb) = (fa.value(q[0], q[1]), fb.value(qm[0], qm[1]));
        worst = worst.max((va - vb).abs() / (1.0 + va.abs()));
        assert!(close(va, vb, 1e-9), "{q:?}: {va} vs {vb}");
        // Gradients rotate with the road.
        let g = fa.gradient(q[0], q[1]);
        let gm = fb.gradient(qm[0], qm[1]);
        let g_rot = rotate_shift(g, angle, [0.0, 0.0]);
        for k in 0..2 {
            assert!(close(g_rot[k], gm[k], 1e-7), "{q:?}: {g_rot:?} vs {gm:?}");
        }
        let ego = [q[0] - 20.0, q[1]];
        let ego_m = rotate_shift(ego, angle, shift);
        let (la, lb) = (
            LaneAttraction::ahead_of(through, &AttractionParams::from(&p), ego[0], ego[1]),
            LaneAttraction::ahead_of(
                b.lane(THROUGH_LANE_ID).unwrap(),
                &AttractionParams::from(&p),
                ego_m[0],
                ego_m[1],
            ),
        );
        assert!(close(la.value(q[0], q[1]), lb.value(qm[0], qm[1]), 1e-9));
        // Eq. 4's heading relative to the lane: the same for a vehicle turned with the map.
        let yaw = 3.0 * rng.next() - 1.5;
        let (ca, cb) = (
            through.centreline(),
            b.lane(THROUGH_LANE_ID).unwrap().centreline(),
        );
        let (ha, hb) = (
            lane_relative_heading_rad(ca, q, yaw),
            lane_relative_heading_rad(cb, qm, yaw + angle),
        );
        assert!((ha - hb).abs() < 1e-9, "{q:?}: {ha} vs {hb}");
    }
    eprintln!("rotated + shifted curved merge: worst relative value difference {worst:.1e}");
}

#[test]
fn an_ending_lane_closes_with_an_edge() {
    // The acceleration lane ending square (no taper): an edge across its end.
    let road = on_ramp(0.0);
    let accel = road.lane(on_ramp_ids::ACCELERATION).unwrap();
    let end = road.lane_end(on_ramp_ids::ACCELERATION).unwrap();
    assert!(end.closed);
    let geometry = LaneRoadGeometry::new(&road);
    let p = PlannerParams::default();
    let field = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m());
    let len = accel.length_m();
    // Eq. 3 measures the distance to the nearest point of each edge: the end is the nearest
    // part of the drivable area's edge within half a lane width (1.75 m) of it. There the field
    // grows towards the end and pushes back along the lane.
    let mut last = 0.0;
    for before in [1.5, 1.0, 0.5] {
        let [x, y] = accel.point(len - before, 0.0);
        let v = field.edge_value(x, y);
        assert!(v > last, "{before} m before the end: {v} ≤ {last}");
        assert!(
            field.edge_gradient(x, y)[0] > 0.0,
            "{before} m before the end"
        );
        last = v;
    }
    // Farther back the lane's side bound is nearer than its end, and no edge pushes along the
    // lane: in particular no edge beyond the gore, whose far side is the drivable main road.
    // (Until an edge's distance was made positive on every drivable point, the main road's
    // right edge, "beyond" which this point lay, pushed it along x with the linear
    // continuation's slope, whatever its distance, and this test asserted that push.)
    for before in [30.0, 10.0, 5.0] {
        let [x, y] = accel.point(len - before, 0.0);
        let along = field.edge_gradient(x, y)[0];
        assert!(along.abs() < 1e-6, "{before} m before the end: {along}");
    }
    // Beyond the end: off the drivable area, the distance to the closed end is negative.
    let [x, y] = accel.point(len + 0.5, 0.0);
    assert!(geometry.edge_distances_m(x, y).iter().any(|d| *d < -0.4));
    // The ending lane of the straight merge road closes with its taper: the field grows along
    // its centreline towards the tip.
    let road = MergeRoad::default();
    let lanes = road.lane_road().unwrap();
    let geometry = LaneRoadGeometry::new(&lanes);
    let field = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m());
    let ending = lanes.lane(ENDING_LANE_ID).unwrap();
    let mut last = 0.0;
    for s in [200.0, 240.0, 270.0, 290.0, 300.0] {
        let [x, y] = ending.point(s, 0.0);
        let v = field.edge_value(x, y);
        assert!(v > last, "s = {s}: {v} ≤ {last}");
        last = v;
    }
}

/// Two lanes on a 200 m-radius left arc whose divider moves across them (the right lane widens
/// by 1 m over 100 m while the left one narrows): the divider term's ∂U/∂s (d_div'(s) ≠ 0) is
/// mapped through the frame too.
#[test]
fn a_moving_divider_has_its_along_lane_gradient() {
    use mergesim_types::lanes::{LaneId, LaneSpec};
    let (r_right, w) = (200.0, 3.5);
    let n = 100;
    let arc = |radius: f64| -> Vec<[f64; 2]> {
        (0..=n)
            .map(|k| {
                let phi = k as f64 / r_right;
                [radius * phi.sin(), r_right - radius * phi.cos()]
            })
            .collect()
    };
    let shift: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
    let right = LaneSpec {
        left: Some(LaneId(1)),
        width_m: Vec::new(),
        left_width_m: shift.iter().map(|t| 0.5 * w + t).collect(),
        right_width_m: vec![0.5 * w],
        ..LaneSpec::new(LaneId(2), arc(r_right), w)
    };
    let left = LaneSpec {
        right: Some(LaneId(2)),
        width_m: Vec::new(),
        left_width_m: vec![0.5 * w],
        right_width_m: shift.iter().map(|t| 0.5 * w - t).collect(),
        ..LaneSpec::new(LaneId(1), arc(r_right - w), w)
    };
    let road = LaneRoad::new(&LaneRoadSpec {
        lanes: vec![left, right],
        tolerances: Default::default(),
    })
    .unwrap();
    let geometry = LaneRoadGeometry::new(&road);
    assert_eq!(geometry.divider_count(), 1);
    let p = PlannerParams::default();
    let field = LaneRoadField::new(&geometry, &RoadFieldParams::from(&p), half_width_m());
    // The ridge follows the divider: its along-lane gradient is the ∂U/∂s term.
    let lane = road.lane(LaneId(2)).unwrap();
    let s = 50.0;
    let (d_div, slope) = lane.bound_d_and_slope(mergesim_types::lanes::Side::Left, s);
    // (s runs along 1 m arcs' chords, 2R sin(1/2R) = 1 − 1.0e-6 m: s = 50 is a hair past k = 50.)
    assert!((d_div - (0.5 * w + 0.5)).abs() < 1e-5 && (slope - 0.01).abs() < 1e-7);
    let q = lane.point(s, d_div - p.lane_sigma_m);
    let g = field.lane_gradient(q[0], q[1]);
    // Along the frame's own ∂p/∂s (∇d is orthogonal to it; the smoothed tangent differs from
    // it by up to half a vertex's turn, enough to mix in ∂U/∂d): ∂U/∂s / |∂p/∂s|, with
    // ∂U/∂s = U δ/σ² · d_div' = −A e^{−½}/σ · 0.01 at δ = −σ.
    let axes = lane.centreline().axes(s, d_div - p.lane_sigma_m);
    let norm = axes.dp_ds[0].hypot(axes.dp_ds[1]);
    let along = (g[0] * axes.dp_ds[0] + g[1] * axes.dp_ds[1]) / norm;
    let expected = -p.lane_amplitude * (-0.5_f64).exp() / p.lane_sigma_m * slope / norm;
    assert!(
        (along - expected).abs() < 1e-9 * expected.abs(),
        "{along} vs {expected}"
    );
    let worst = check_gradients(&road, 2000, |r| {
        lane.point(-10.0 + 120.0 * r.next(), -3.0 + 10.0 * r.next())
    });
    eprintln!("moving divider: worst relative gradient error {worst:.1e}");
}
