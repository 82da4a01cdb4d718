//! Roads made of lanes, the road: the merge road through lanes, the drivable area (shared
//! bounds, lane ends), links, refusal of inconsistent data, the builders, TOML.

use mergesim_types::lanes::{
    ENDING_LANE_ID, LaneError, LaneId, LaneKind, LaneRoad, LaneRoadSpec, LaneSpec, LaneTolerances,
    OnRampParams, THROUGH_LANE_ID, curved_merge_spec, on_ramp_ids, on_ramp_spec,
};
use mergesim_types::{Lane as MergeLane, MergeRoad};

const R: f64 = 300.0;

fn curved() -> LaneRoad {
    LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), R).unwrap()).unwrap()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Interpolated y of an x-monotone polyline at x.
fn y_at(poly: &[[f64; 2]], x: f64) -> Option<f64> {
    poly.windows(2).find_map(|w| {
        (w[0][0] <= x && x <= w[1][0] && w[1][0] > w[0][0])
            .then(|| w[0][1] + (w[1][1] - w[0][1]) * (x - w[0][0]) / (w[1][0] - w[0][0]))
    })
}

/// Distance from p to a polyline.
fn dist_to_polyline(poly: &[[f64; 2]], p: [f64; 2]) -> f64 {
    poly.windows(2)
        .map(|w| {
            let e = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
            let t = (((p[0] - w[0][0]) * e[0] + (p[1] - w[0][1]) * e[1])
                / (e[0] * e[0] + e[1] * e[1]))
                .clamp(0.0, 1.0);
            dist(p, [w[0][0] + t * e[0], w[0][1] + t * e[1]])
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn merge_road_as_lanes() {
    let road = MergeRoad::default();
    let lanes = road.lane_road().unwrap();
    let through = lanes.lane(MergeRoad::lane_id(MergeLane::Upper)).unwrap();
    let ending = lanes.lane(MergeRoad::lane_id(MergeLane::Lower)).unwrap();
    // Lane centres.
    for x in [-50.0, 0.0, 100.0, 159.0, 200.0, 259.0] {
        let fp = ending.project([x, road.lane_center_y_m(MergeLane::Lower)]);
        assert!(fp.d_m.abs() < 1e-12 && (fp.s_m - (x - road.start_x_m)).abs() < 1e-9);
    }
    for x in [-50.0, 100.0, 400.0, 700.0] {
        assert!(
            through
                .project([x, road.lane_center_y_m(MergeLane::Upper)])
                .d_m
                .abs()
                < 1e-12
        );
    }
    // One divider, at y_lane, from the start to the merge end (has_divider).
    let div = lanes.dividers();
    assert_eq!(div.len(), 1);
    assert_eq!(
        (div[0].left_lane, div[0].right_lane),
        (THROUGH_LANE_ID, ENDING_LANE_ID)
    );
    let first = div[0].polyline_m[0];
    let last = div[0].polyline_m[div[0].polyline_m.len() - 1];
    assert!((first[0] - road.start_x_m).abs() < 1e-9);
    assert!((last[0] - road.merge_end_x_m).abs() < 1e-9);
    for p in &div[0].polyline_m {
        assert!((p[1] - road.y_lane_m()).abs() < 1e-12);
    }
    // Outer edges: the upper edge and the piecewise lower edge (with the taper and the lane end).
    let edges = lanes.outer_edges();
    assert_eq!(edges.len(), 2, "{edges:?}");
    let lower = edges
        .iter()
        .find(|e| e.polyline_m[0][1] < road.y_lane_m())
        .unwrap();
    let upper = edges
        .iter()
        .find(|e| e.polyline_m[0][1] > road.y_lane_m())
        .unwrap();
    assert_eq!(lower.polyline_m.len(), road.lower_edge_polyline().len());
    for (a, b) in lower.polyline_m.iter().zip(road.lower_edge_polyline()) {
        assert!(dist(*a, b) < 1e-9, "{a:?} vs {b:?}");
    }
    for i in 0..=1500 {
        let x = road.start_x_m + (road.end_x_m - road.start_x_m) * i as f64 / 1500.0;
        let y = y_at(&lower.polyline_m, x).unwrap();
        assert!((y - road.lower_edge_y_m(x)).abs() < 1e-9, "x = {x}");
        assert!((y_at(&upper.polyline_m, x).unwrap() - road.y_upper_m()).abs() < 1e-12);
    }
    // The ending lane's end: closed, at the merge end, of zero width (the taper's tip).
    let end = lanes.lane_end(ENDING_LANE_ID).unwrap();
    assert!(end.closed);
    assert!((end.edge_m[0][0] - road.merge_end_x_m).abs() < 1e-9);
    assert!(dist(end.edge_m[0], end.edge_m[1]) < 1e-9);
    assert!(!lanes.lane_end(THROUGH_LANE_ID).unwrap().closed);
    // On the road, and the signed distance to the edges, at many points (off the boundaries).
    let mut inside = 0;
    for i in 0..120 {
        for j in 0..40 {
            let x = road.start_x_m - 5.0 + 760.0 * (i as f64 + 0.31) / 120.0;
            let y = road.y_bottom_m - 1.0 + 9.0 * (j as f64 + 0.27) / 40.0;
            let on_road = x >= road.start_x_m
                && x <= road.end_x_m
                && y >= road.lower_edge_y_m(x)
                && y <= road.y_upper_m();
            assert_eq!(lanes.is_drivable([x, y]), on_road, "({x}, {y})");
            inside += usize::from(on_road);
            let d = dist_to_polyline(&road.lower_edge_polyline(), [x, y])
                .min(dist_to_polyline(&road.upper_edge_polyline(), [x, y]));
            let expected = if on_road { d } else { -d };
            let got = lanes.signed_distance_to_edge_m([x, y]);
            assert!(
                (got - expected).abs() < 1e-9,
                "({x}, {y}): {got} vs {expected}"
            );
        }
    }
    assert!(inside > 1000);
    // Which lane: both lanes before the taper's start hold a point on the divider.
    let hits = lanes.lanes_at([100.0, road.y_lane_m()]);
    assert_eq!(hits.len(), 2);
    assert_eq!(lanes.nearest_lane([100.0, 1.0]).lane, ENDING_LANE_ID);
    assert_eq!(lanes.nearest_lane([400.0, 1.0]).lane, THROUGH_LANE_ID);
}

#[test]
fn curved_merge_road_has_its_divider_and_closed_end() {
    let road = curved();
    let m = MergeRoad::default();
    assert_eq!(road.dividers().len(), 1);
    assert_eq!(road.outer_edges().len(), 2);
    let end = road.lane_end(ENDING_LANE_ID).unwrap();
    assert!(end.closed);
    let ending = road.lane(ENDING_LANE_ID).unwrap();
    // The ending lane is the outer one on a left curve: its length scales by (R + w/2)/R.
    let expected = (m.merge_end_x_m - m.start_x_m) * (R + 0.5 * m.lane_width_m) / R;
    assert!(
        (ending.length_m() - expected).abs() < 1e-3,
        "{}",
        ending.length_m()
    );
    // Mid-taper: the drivable part of the ending lane is the upper half.
    let s = (0.5 * (m.merge_start_x_m + m.merge_end_x_m) - m.start_x_m)
        * (R + 0.5 * m.lane_width_m)
        / R;
    assert!(road.is_drivable(ending.point(s, 0.2)));
    assert!(!road.is_drivable(ending.point(s, -0.2)));
    assert!((road.signed_distance_to_edge_m(ending.point(s, 0.2)) - 0.2).abs() < 0.01);
}

#[test]
fn shared_bound_is_not_a_wall() {
    let p = OnRampParams::default();
    let road = LaneRoad::new(&on_ramp_spec(&p).unwrap()).unwrap();
    let w = p.lane_width_m;
    // On the divider between the right main lane and the acceleration lane: drivable, and the
    // nearest wall is a lane width away (the acceleration lane's right bound), not here.
    let x = p.accel_start_x_m + 100.0;
    assert!(road.is_drivable([x, 0.0]));
    assert!((road.signed_distance_to_edge_m([x, 0.0]) - w).abs() < 1e-9);
    // Before the acceleration lane, the same line is the road's edge.
    assert!(road.signed_distance_to_edge_m([50.0, 0.0]).abs() < 1e-9);
    assert!(road.signed_distance_to_edge_m([50.0, -0.1]) < 0.0);
    // Dividers: 1|2 over the whole road, 2|3 along the acceleration lane.
    let d23 = road
        .dividers()
        .iter()
        .find(|d| d.right_lane == on_ramp_ids::ACCELERATION)
        .unwrap();
    assert_eq!(d23.left_lane, on_ramp_ids::MAIN_RIGHT);
    assert!((d23.polyline_m[0][0] - p.accel_start_x_m).abs() < 1e-6);
    let end_x = d23.polyline_m[d23.polyline_m.len() - 1][0];
    assert!((end_x - (p.accel_start_x_m + p.accel_length_m + p.taper_length_m)).abs() < 1e-6);
    assert!(
        road.dividers()
            .iter()
            .any(|d| d.left_lane == on_ramp_ids::MAIN_LEFT
                && d.right_lane == on_ramp_ids::MAIN_RIGHT)
    );
    // The ramp curves right at 1/150 m.
    let ramp = road.lane(on_ramp_ids::RAMP).unwrap();
    assert_eq!(ramp.kind(), LaneKind::Entry);
    assert!((ramp.curvature_1pm(0.5 * ramp.length_m()) * p.ramp_radius_m + 1.0).abs() < 1e-5);
    assert_eq!(
        road.lane(on_ramp_ids::ACCELERATION).unwrap().predecessors(),
        &[on_ramp_ids::RAMP]
    );
    assert_eq!(ramp.successors(), &[on_ramp_ids::ACCELERATION]);
}

#[test]
fn lane_end_closes() {
    let p = OnRampParams {
        taper_length_m: 0.0,
        ..OnRampParams::default()
    };
    let road = LaneRoad::new(&on_ramp_spec(&p).unwrap()).unwrap();
    let w = p.lane_width_m;
    let x_end = p.accel_start_x_m + p.accel_length_m;
    let end = road.lane_end(on_ramp_ids::ACCELERATION).unwrap();
    assert!(end.closed);
    assert!(dist(end.edge_m[0], [x_end, -w]) < 1e-9);
    assert!(dist(end.edge_m[1], [x_end, 0.0]) < 1e-9);
    // Main lanes end open at the road's end.
    assert!(!road.lane_end(on_ramp_ids::MAIN_RIGHT).unwrap().closed);
    // Just before the end: drivable, 0.3 m from the edge across the end.
    assert!((road.signed_distance_to_edge_m([x_end - 0.3, -0.5 * w]) - 0.3).abs() < 1e-9);
    assert!(!road.is_drivable([x_end + 0.3, -0.5 * w]));
    assert!((road.signed_distance_to_edge_m([x_end + 0.3, -0.5 * w]) + 0.3).abs() < 1e-9);
    // The right edge runs along the acceleration lane, across its end, then along lane 2.
    let chained = road.outer_edges().iter().find(|e| {
        e.polyline_m
            .windows(2)
            .any(|s| dist(s[0], [x_end, -w]) < 1e-9 && dist(s[1], [x_end, 0.0]) < 1e-9)
    });
    let chained = chained.expect("an edge across the acceleration lane's end");
    let last = chained.polyline_m[chained.polyline_m.len() - 1];
    assert!(dist(last, [p.main_length_m, 0.0]) < 1e-9, "{last:?}");
}

#[test]
fn y_merge_joins_two_lanes_into_one() {
    let w = 3.5;
    let mut a = LaneSpec::new(LaneId(1), vec![[0.0, 2.0], [50.0, 0.5]], w);
    a.successors = vec![LaneId(3)];
    let mut b = LaneSpec::new(LaneId(2), vec![[0.0, -2.0], [50.0, -0.5]], w);
    b.successors = vec![LaneId(3)];
    let c = LaneSpec::new(LaneId(3), vec![[50.0, 0.0], [150.0, 0.0]], w);
    let road = LaneRoad::new(&LaneRoadSpec {
        lanes: vec![a, b, c],
        tolerances: LaneTolerances::default(),
    })
    .unwrap();
    assert_eq!(
        road.lane(LaneId(3)).unwrap().predecessors(),
        &[LaneId(1), LaneId(2)]
    );
    assert!(road.is_drivable([49.0, 0.0]));
    assert!(road.is_drivable([100.0, 1.7]));
    assert!(road.lane_end(LaneId(1)).is_none());
}

fn two_lanes() -> LaneRoadSpec {
    let mut a = LaneSpec::new(LaneId(1), vec![[0.0, 1.75], [100.0, 1.75]], 3.5);
    a.left = Some(LaneId(2));
    let mut b = LaneSpec::new(LaneId(2), vec![[0.0, 5.25], [100.0, 5.25]], 3.5);
    b.right = Some(LaneId(1));
    b.successors = vec![LaneId(3)];
    let c = LaneSpec::new(LaneId(3), vec![[100.0, 5.25], [200.0, 5.25]], 3.5);
    LaneRoadSpec {
        lanes: vec![a, b, c],
        tolerances: LaneTolerances::default(),
    }
}

fn refused(edit: impl FnOnce(&mut LaneRoadSpec)) -> LaneError {
    let mut spec = two_lanes();
    edit(&mut spec);
    LaneRoad::new(&spec).unwrap_err()
}

#[test]
fn inconsistent_lane_data_is_refused_naming_lane_and_field() {
    assert!(LaneRoad::new(&two_lanes()).is_ok());
    let cases: Vec<(LaneError, Option<u32>, &str, &str)> = vec![
        (refused(|s| s.lanes.clear()), None, "lanes", "no lanes"),
        (
            refused(|s| s.lanes[2].id = LaneId(1)),
            Some(1),
            "id",
            "used by two",
        ),
        (
            refused(|s| s.lanes[0].centreline_m[1][0] = f64::NAN),
            Some(1),
            "centreline_m",
            "not finite",
        ),
        (
            refused(|s| s.lanes[0].centreline_m = vec![[0.0, 0.0], [0.0, 0.0], [0.01, 0.0]]),
            Some(1),
            "centreline_m",
            "1 distinct",
        ),
        (
            refused(|s| s.lanes[2].centreline_m = vec![[100.0, 5.25], [150.0, 5.25], [120.0, 5.3]]),
            Some(3),
            "centreline_m",
            "turns",
        ),
        (
            refused(|s| s.lanes[0].width_m = vec![3.5, 3.0, 2.0]),
            Some(1),
            "width_m",
            "3 values",
        ),
        (
            refused(|s| s.lanes[0].width_m.clear()),
            Some(1),
            "width_m",
            "missing",
        ),
        (
            refused(|s| s.lanes[0].left_width_m = vec![1.0]),
            Some(1),
            "width_m",
            "alone",
        ),
        (
            refused(|s| {
                s.lanes[0].width_m.clear();
                s.lanes[0].left_width_m = vec![1.0];
            }),
            Some(1),
            "right_width_m",
            "missing",
        ),
        (
            refused(|s| s.lanes[1].width_m = vec![-3.5]),
            Some(2),
            "width_m",
            "positive",
        ),
        (
            refused(|s| {
                s.lanes[2].centreline_m.insert(1, [150.0, 5.25]);
                s.lanes[2].width_m = vec![3.5, 0.0, 3.5];
            }),
            Some(3),
            "width_m",
            "positive",
        ),
        (
            refused(|s| s.lanes[1].successors = vec![LaneId(9)]),
            Some(2),
            "successors",
            "does not exist",
        ),
        (
            refused(|s| s.lanes[0].left = Some(LaneId(1))),
            Some(1),
            "left",
            "itself",
        ),
        (
            refused(|s| s.lanes[2].centreline_m = vec![[101.0, 5.25], [200.0, 5.25]]),
            Some(2),
            "successors",
            "from the start of lane 3",
        ),
        (
            refused(|s| {
                s.lanes[1].successors.clear();
                s.lanes[2].predecessors = vec![LaneId(2)];
                s.lanes[2].centreline_m = vec![[100.0, 9.0], [200.0, 9.0]];
            }),
            Some(3),
            "predecessors",
            "lane 2 ends",
        ),
        (
            refused(|s| s.lanes[1].centreline_m = vec![[0.0, 6.0], [100.0, 6.0]]),
            Some(1),
            "left",
            "not beside",
        ),
        (
            // Beside, but driving the other way.
            refused(|s| {
                s.lanes[1].centreline_m = vec![[100.0, 5.25], [0.0, 5.25]];
                s.lanes[1].successors.clear();
            }),
            Some(1),
            "left",
            "not beside",
        ),
        (
            refused(|s| s.tolerances.link_m = 0.0),
            None,
            "link_m",
            "(0, 5]",
        ),
    ];
    for (err, lane, field, words) in cases {
        let msg = err.to_string();
        assert_eq!(err.lane().map(|l| l.0), lane, "{msg}");
        assert_eq!(err.field(), field, "{msg}");
        assert!(msg.contains(words), "{msg:?} lacks {words:?}");
        if let Some(l) = lane {
            assert!(msg.starts_with(&format!("lane {l}: {field}")), "{msg}");
        }
    }
}

#[test]
fn lane_data_reads_from_toml() {
    let text = r#"
        [[lanes]]
        id = 1
        centreline_m = [[0.0, 1.75], [100.0, 1.75]]
        width_m = [3.5]
        left = 2

        [[lanes]]
        id = 2
        kind = "entry"
        centreline_m = [[0.0, 5.25], [50.0, 5.25], [100.0, 5.25]]
        left_width_m = [1.75]
        right_width_m = [1.75, 1.75, 1.75]
        right = 1

        [tolerances]
        vertex_merge_m = 0.01
    "#;
    let spec: LaneRoadSpec = toml::from_str(text).unwrap();
    assert_eq!(spec.lanes[1].kind, LaneKind::Entry);
    assert_eq!(spec.tolerances.vertex_merge_m, 0.01);
    let road = LaneRoad::new(&spec).unwrap();
    assert_eq!(road.dividers().len(), 1);
    // And back.
    let again: LaneRoadSpec = toml::from_str(&toml::to_string(&spec).unwrap()).unwrap();
    assert_eq!(again, spec);
    let bad = toml::from_str::<LaneRoadSpec>("[[lanes]]\nid = 1\ncentreline = []\n");
    assert!(bad.unwrap_err().to_string().contains("centreline"));
}

#[test]
fn bound_inside_another_lane_is_not_a_wall() {
    // A shoulder drawn overlapping half of the main lane (its left bound lies inside the main
    // lane, the main lane's right bound inside the shoulder): only the two outer lines are walls.
    let main = LaneSpec::new(LaneId(1), vec![[0.0, 1.75], [100.0, 1.75]], 3.5);
    let shoulder = LaneSpec {
        kind: LaneKind::Shoulder,
        ..LaneSpec::new(LaneId(2), vec![[0.0, 0.0], [100.0, 0.0]], 2.5)
    };
    let road = LaneRoad::new(&LaneRoadSpec {
        lanes: vec![main, shoulder],
        tolerances: LaneTolerances::default(),
    })
    .unwrap();
    let mut ys: Vec<f64> = road
        .outer_edges()
        .iter()
        .map(|e| {
            assert!(e.polyline_m.iter().all(|p| p[1] == e.polyline_m[0][1]));
            e.polyline_m[0][1]
        })
        .collect();
    ys.sort_by(f64::total_cmp);
    assert_eq!(ys, vec![-1.25, 3.5]);
    for y in [-1.0, 0.0, 1.25, 1.3, 3.4] {
        assert!(road.is_drivable([50.0, y]));
        let expected = (y + 1.25).min(3.5 - y);
        assert!((road.signed_distance_to_edge_m([50.0, y]) - expected).abs() < 1e-9);
    }
    assert!(road.dividers().is_empty());
}

#[test]
fn builders_refuse_bad_parameters() {
    let e = curved_merge_spec(&MergeRoad::default(), 5.0).unwrap_err();
    assert_eq!(e.name, "radius_m");
    assert!(curved_merge_spec(&MergeRoad::default(), f64::NAN).is_err());
    // 750 m of road on a 100 m radius would turn 7.5 rad.
    assert!(curved_merge_spec(&MergeRoad::default(), 100.0).is_err());
    assert!(curved_merge_spec(&MergeRoad::default(), -300.0).is_ok());
    let short = OnRampParams {
        main_length_m: 400.0,
        ..OnRampParams::default()
    };
    assert_eq!(
        on_ramp_spec(&short).unwrap_err().name,
        "on_ramp.main_length_m"
    );
    let huge = OnRampParams {
        ramp_radius_m: 1e300,
        ..OnRampParams::default()
    };
    assert_eq!(
        on_ramp_spec(&huge).unwrap_err().name,
        "on_ramp.ramp_radius_m"
    );
    // A right curve builds and curves right.
    let right = LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), -300.0).unwrap()).unwrap();
    let lane = right.lane(THROUGH_LANE_ID).unwrap();
    assert!((lane.curvature_1pm(100.0) * (300.0 + 1.75) + 1.0).abs() < 1e-5);
}

#[test]
fn distance_to_a_closed_end_follows_successors() {
    let m = MergeRoad::default();
    let merge = m.lane_road().unwrap();
    let d = merge
        .distance_to_closed_end_m(ENDING_LANE_ID, 10.0)
        .unwrap();
    assert!((d - (m.merge_end_x_m - m.start_x_m - 10.0)).abs() < 1e-9);
    assert_eq!(merge.distance_to_closed_end_m(THROUGH_LANE_ID, 10.0), None);
    let p = OnRampParams::default();
    let ramp_road = LaneRoad::new(&on_ramp_spec(&p).unwrap()).unwrap();
    let ramp_len = ramp_road.lane(on_ramp_ids::RAMP).unwrap().length_m();
    let d = ramp_road
        .distance_to_closed_end_m(on_ramp_ids::RAMP, 0.0)
        .unwrap();
    assert!((d - (ramp_len + p.accel_length_m + p.taper_length_m)).abs() < 1e-9);
    assert_eq!(
        ramp_road.distance_to_closed_end_m(on_ramp_ids::MAIN_RIGHT, 0.0),
        None
    );
    assert_eq!(ramp_road.distance_to_closed_end_m(LaneId(99), 0.0), None);
}
