//! What a drawing of a road made of lanes shows, shared by the recording, the GIF and the PNG
//! figures: the drivable area's outer edges (solid), the dividers between same-direction lanes
//! (dashed), the closed ends of lanes that end, the tapering stretch of those lanes (the merge
//! section, shaded), and where each lane's id goes when asked for. Pure geometry in the road's
//! own coordinates (m); each output draws it in its own way.

use mergesim_types::lanes::{LaneRoad, Side};

/// Length of a divider's dashes and of the gaps between them (m): the 3 m / 6 m marking of
/// German motorway lane lines would vanish in the whole-road views, so 4 m / 4 m.
pub const DASH_M: f64 = 4.0;
/// Gap between a divider's dashes (m).
pub const DASH_GAP_M: f64 = 4.0;

/// A closed lane end shorter than this (the tip of a taper) is not drawn on its own (m).
const MIN_END_M: f64 = 0.01;

/// Where a lane's id is written.
#[derive(Clone, Debug, PartialEq)]
pub struct LaneLabel {
    /// The text ("lane 1").
    pub text: String,
    /// The point (m): the lane's centreline at half its length.
    pub at_m: [f64; 2],
    /// The lane's heading there (rad).
    pub heading_rad: f64,
}

/// The drawing of a road (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct RoadDrawing {
    /// The drivable area's outer edges (closed lane ends included), solid.
    pub outer_edges: Vec<Vec<[f64; 2]>>,
    /// The dividers between same-direction lanes, whole (see `dashes` to dash them).
    pub dividers: Vec<Vec<[f64; 2]>>,
    /// The closed ends of lanes that end, from the right bound to the left, those of a
    /// non-zero length (a taper's tip has none).
    pub closed_ends: Vec<[[f64; 2]; 2]>,
    /// The tapering stretch of each lane with a closed end (where its width falls below its
    /// widest, to its end), as a polygon: its left bound forwards, its right bound back.
    pub merge_sections: Vec<Vec<[f64; 2]>>,
    /// The centreline of each merge section (for outputs that draw it as a wide band) and the
    /// section's widest width (m).
    pub merge_section_centrelines: Vec<(Vec<[f64; 2]>, f64)>,
    /// One label per lane.
    pub lane_labels: Vec<LaneLabel>,
    /// Bounding box of every lane's bounds, `[min, max]` (m).
    pub bounds_m: [[f64; 2]; 2],
}

impl RoadDrawing {
    /// The drawing of `lanes`.
    pub fn new(lanes: &LaneRoad) -> Self {
        let outer_edges = lanes
            .outer_edges()
            .iter()
            .map(|e| e.polyline_m.clone())
            .collect();
        let dividers = lanes
            .dividers()
            .iter()
            .map(|d| d.polyline_m.clone())
            .collect();
        let closed_ends = lanes
            .lane_ends()
            .iter()
            .filter(|e| e.closed && dist(e.edge_m[0], e.edge_m[1]) > MIN_END_M)
            .map(|e| e.edge_m)
            .collect();
        let mut merge_sections = Vec::new();
        let mut merge_section_centrelines = Vec::new();
        for end in lanes.lane_ends().iter().filter(|e| e.closed) {
            let Some(lane) = lanes.lane(end.lane) else {
                continue;
            };
            let vertex_s = lane.centreline().vertex_s_m();
            let widest = vertex_s
                .iter()
                .map(|&s| lane.width_m(s))
                .fold(0.0_f64, f64::max);
            // The last vertex at the lane's widest: the taper starts there.
            let start = vertex_s
                .iter()
                .copied()
                .filter(|&s| lane.width_m(s) >= widest - 1e-6)
                .fold(f64::NAN, f64::max);
            // (NaN: no vertex at the widest, nothing to shade.)
            if start.is_nan() || start >= end.s_m {
                continue;
            }
            let mut ss: Vec<f64> = vec![start];
            ss.extend(
                vertex_s
                    .iter()
                    .copied()
                    .filter(|&s| s > start && s < end.s_m),
            );
            ss.push(end.s_m);
            let left: Vec<[f64; 2]> = ss
                .iter()
                .map(|&s| lane.point(s, lane.bound_d_m(Side::Left, s)))
                .collect();
            let right = ss
                .iter()
                .rev()
                .map(|&s| lane.point(s, lane.bound_d_m(Side::Right, s)));
            merge_sections.push(left.into_iter().chain(right).collect());
            merge_section_centrelines.push((
                ss.iter()
                    .map(|&s| {
                        let mid = 0.5 * (lane.left_d_m(s) + lane.right_d_m(s));
                        lane.point(s, mid)
                    })
                    .collect(),
                widest,
            ));
        }
        let lane_labels = lanes
            .lanes()
            .iter()
            .map(|l| {
                let s = 0.5 * l.length_m();
                LaneLabel {
                    text: format!("lane {}", l.id()),
                    at_m: l.point(s, 0.0),
                    heading_rad: l.heading_rad(s),
                }
            })
            .collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for lane in lanes.lanes() {
            for side in [Side::Left, Side::Right] {
                for p in lane.bound_polyline(side) {
                    for k in 0..2 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
        }
        Self {
            outer_edges,
            dividers,
            closed_ends,
            merge_sections,
            merge_section_centrelines,
            lane_labels,
            bounds_m: [lo, hi],
        }
    }

    /// The dividers cut into dashes of [`DASH_M`] with gaps of [`DASH_GAP_M`].
    pub fn divider_dashes(&self) -> Vec<Vec<[f64; 2]>> {
        self.dividers
            .iter()
            .flat_map(|d| dashes(d, DASH_M, DASH_GAP_M))
            .collect()
    }

    /// The lowest and highest Y (m) of the road's bounds over the X range `x_range_m` (each
    /// bound polyline clipped to it, so exact); the bounds' whole Y range if no bound reaches
    /// into it.
    pub fn y_range_over_m(&self, lanes: &LaneRoad, x_range_m: [f64; 2]) -> [f64; 2] {
        let [x0, x1] = x_range_m;
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for lane in lanes.lanes() {
            for side in [Side::Left, Side::Right] {
                for w in lane.bound_polyline(side).windows(2) {
                    let (a, b) = if w[0][0] <= w[1][0] {
                        (w[0], w[1])
                    } else {
                        (w[1], w[0])
                    };
                    let (c0, c1) = (a[0].max(x0), b[0].min(x1));
                    if c0 > c1 {
                        continue;
                    }
                    let y_at = |x: f64| {
                        if b[0] > a[0] {
                            a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
                        } else {
                            a[1].min(b[1])
                        }
                    };
                    let ys = if b[0] > a[0] {
                        [y_at(c0), y_at(c1)]
                    } else {
                        [a[1], b[1]]
                    };
                    for y in ys {
                        lo = lo.min(y);
                        hi = hi.max(y);
                    }
                }
            }
        }
        if lo <= hi {
            [lo, hi]
        } else {
            [self.bounds_m[0][1], self.bounds_m[1][1]]
        }
    }
}

/// The lateral offset (m, d in lane `id`'s frame, left positive) of the middle of the road
/// across that lane: halfway between the lane's leftmost left bound plus the widest widths of
/// its chain of left neighbours, and its rightmost right bound minus those of its right
/// neighbours. Constant along the lane and the same line from each of the lanes side by side
/// (on the merge road: the divider, from either lane, also beyond the lane's end), so a view
/// centred on it does not jump at lane ends or lane changes. 0 for an unknown lane.
pub fn road_middle_offset_m(lanes: &LaneRoad, id: mergesim_types::lanes::LaneId) -> f64 {
    let Some(lane) = lanes.lane(id) else {
        return 0.0;
    };
    let at_vertices = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
        lane.centreline()
            .vertex_s_m()
            .iter()
            .map(|&s| f(s))
            .collect()
    };
    let left = at_vertices(&|s| lane.left_d_m(s))
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max);
    let right = at_vertices(&|s| lane.right_d_m(s))
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    let chain = |side: Side| {
        let mut seen = vec![id];
        let mut total = 0.0;
        let mut next = lane.neighbour(side);
        while let Some(n) = next {
            if seen.contains(&n) {
                break;
            }
            seen.push(n);
            total += widest_width_m(lanes, n);
            next = lanes.lane(n).and_then(|l| l.neighbour(side));
        }
        total
    };
    let top = left + chain(Side::Left);
    let bottom = right - chain(Side::Right);
    if top.is_finite() && bottom.is_finite() {
        0.5 * (top + bottom)
    } else {
        0.0
    }
}

/// The widest width of lane `id` over its vertices (m; 0 for an unknown lane).
fn widest_width_m(lanes: &LaneRoad, id: mergesim_types::lanes::LaneId) -> f64 {
    lanes.lane(id).map_or(0.0, |l| {
        l.centreline()
            .vertex_s_m()
            .iter()
            .map(|&s| l.width_m(s))
            .fold(0.0_f64, f64::max)
    })
}

/// The largest width of the road across (m): over every lane, the sum of the widest widths of
/// the lane and of its chains of left and right neighbours. (The merge road: 7 m.)
pub fn road_width_m(lanes: &LaneRoad) -> f64 {
    let widest = |id| widest_width_m(lanes, id);
    let mut best: f64 = 0.0;
    for lane in lanes.lanes() {
        let mut total = widest(lane.id());
        for side in [Side::Left, Side::Right] {
            let mut seen = vec![lane.id()];
            let mut next = lane.neighbour(side);
            while let Some(id) = next {
                if seen.contains(&id) {
                    break;
                }
                seen.push(id);
                total += widest(id);
                next = lanes.lane(id).and_then(|l| l.neighbour(side));
            }
        }
        best = best.max(total);
    }
    best
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// `polyline` cut into dashes `dash_m` long with gaps `gap_m` long, starting with a dash (a
/// dash going round a vertex keeps it). A non-positive dash gives the polyline whole.
pub(crate) fn dashes(polyline: &[[f64; 2]], dash_m: f64, gap_m: f64) -> Vec<Vec<[f64; 2]>> {
    if !(dash_m > 0.0 && gap_m >= 0.0 && (dash_m + gap_m).is_finite()) {
        return vec![polyline.to_vec()];
    }
    let mut out = Vec::new();
    let mut current: Vec<[f64; 2]> = Vec::new();
    let mut in_dash = true;
    let mut next_boundary_m = dash_m;
    let mut s_a = 0.0;
    for w in polyline.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = dist(a, b);
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        let s_b = s_a + len;
        let at = |s: f64| {
            let t = ((s - s_a) / len).clamp(0.0, 1.0);
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        };
        if in_dash && current.is_empty() {
            current.push(a);
        }
        while next_boundary_m <= s_b {
            if in_dash {
                current.push(at(next_boundary_m));
                out.push(std::mem::take(&mut current));
                next_boundary_m += gap_m;
            } else {
                current = vec![at(next_boundary_m)];
                next_boundary_m += dash_m;
            }
            in_dash = !in_dash;
        }
        if in_dash {
            current.push(b);
        }
        s_a = s_b;
    }
    if in_dash && current.len() >= 2 {
        out.push(current);
    }
    out.retain(|d| d.len() >= 2);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashes_alternate_along_a_bent_line() {
        let line = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]];
        let d = dashes(&line, 4.0, 4.0);
        // Dashes over [0, 4], [8, 12] (round the corner), [16, 20].
        assert_eq!(d.len(), 3, "{d:?}");
        assert_eq!(d[0], vec![[0.0, 0.0], [4.0, 0.0]]);
        assert_eq!(d[1].first(), Some(&[8.0, 0.0]));
        assert_eq!(d[1].last(), Some(&[10.0, 2.0]));
        assert_eq!(d[2], vec![[10.0, 6.0], [10.0, 10.0]]);
    }

    #[test]
    fn the_merge_road_draws_as_today() {
        let road = mergesim_types::MergeRoad::default();
        let lanes = road.lane_road().unwrap_or_else(|e| panic!("{e}"));
        let drawing = RoadDrawing::new(&lanes);
        assert_eq!(drawing.outer_edges.len(), 2);
        assert_eq!(drawing.dividers.len(), 1);
        // The taper ends in a tip: no closed end of its own.
        assert!(drawing.closed_ends.is_empty());
        // The merge section: the ending lane from merge_start to merge_end.
        let section = &drawing.merge_sections[0];
        let xs: Vec<f64> = section.iter().map(|p| p[0]).collect();
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((lo - road.merge_start_x_m).abs() < 1e-9, "{lo}");
        assert!((hi - road.merge_end_x_m).abs() < 1e-9, "{hi}");
        assert!((road_width_m(&lanes) - 2.0 * road.lane_width_m).abs() < 1e-9);
        // The road's middle (the divider, y = 3.5 m) from either lane.
        use mergesim_types::lanes::{ENDING_LANE_ID, THROUGH_LANE_ID};
        let through = road.lane_center_y_m(mergesim_types::Lane::Upper);
        let ending = road.lane_center_y_m(mergesim_types::Lane::Lower);
        let from_through = through + road_middle_offset_m(&lanes, THROUGH_LANE_ID);
        let from_ending = ending + road_middle_offset_m(&lanes, ENDING_LANE_ID);
        assert!(
            (from_through - road.y_lane_m()).abs() < 1e-9,
            "{from_through}"
        );
        assert!(
            (from_ending - road.y_lane_m()).abs() < 1e-9,
            "{from_ending}"
        );
        assert_eq!(drawing.lane_labels.len(), 2);
    }
}
