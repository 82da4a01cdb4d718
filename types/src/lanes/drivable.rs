//! Builds the drivable area's outer edges, the dividers and the lane ends of a
//! [`LaneRoad`]: a bound is a wall only where nothing drivable lies just beyond it.
//!
//! Method: along each bound, sample the lane's own vertices plus the projections of every
//! overlapping lane's bound vertices and end points (where coverage can change), and the
//! midpoints between samples. At each sample, test the point `NUDGE_M` (= [`SLIVER_M`]) beyond
//! the bound (in the lane's frame) against the other lanes. Where the answer changes between two
//! samples, bisect to 1e-10 of the interval, then snap to a sample within `SNAP_M` (the nudge
//! shifts a transition where a lane ends in a taper of slope k beside the bound by NUDGE_M / k).

use rstar::RTree;
use rstar::primitives::{GeomWithData, Line};

use super::lane::Side;
use super::lane_road::{Divider, LaneEnd, LaneRoad, OuterEdge, SLIVER_M};

/// How far beyond a bound the coverage test looks (m): a lane within this beyond a bound makes
/// it interior, so slivers narrower than [`SLIVER_M`] do not make walls.
const NUDGE_M: f64 = SLIVER_M;
/// A coverage transition this close to a sample is moved onto it (m). Where a lane ends in a
/// taper of slope k beside the bound, the nudge moves the transition by NUDGE_M / k (0.14 m on
/// the merge road, k = 3.5/100); the samples hold the true place (the taper's tip).
const SNAP_M: f64 = 0.25;
/// How far ahead of a lane's end (and beside it) a continuing neighbour is looked for (m): more
/// than [`SLIVER_M`], so that lanes ending together at the road's end stay open.
const AHEAD_M: f64 = 0.05;
/// Pieces whose ends lie this close are chained (m).
const CHAIN_M: f64 = SLIVER_M;

/// The sub-intervals of `[samples[0], samples[last]]` (sorted samples) where `pred` holds.
fn true_intervals(samples: &[f64], pred: &dyn Fn(f64) -> bool) -> Vec<[f64; 2]> {
    // Samples (snap targets) and midpoints (checks only).
    let mut pts: Vec<(f64, bool, bool)> = Vec::with_capacity(2 * samples.len());
    for (i, &s) in samples.iter().enumerate() {
        if i > 0 {
            let m = 0.5 * (samples[i - 1] + s);
            pts.push((m, pred(m), false));
        }
        pts.push((s, pred(s), true));
    }
    let mut out = Vec::new();
    let mut start = pts[0].1.then_some(pts[0].0);
    for w in pts.windows(2) {
        let ((a, va, sa), (b, vb, sb)) = (w[0], w[1]);
        if va == vb {
            continue;
        }
        let (mut lo, mut hi) = (a, b);
        while hi - lo > 1e-10 * (b - a).max(1e-9) {
            let m = 0.5 * (lo + hi);
            // Samples a few ulps apart (bounds far along a long lane): stop when the
            // midpoint can no longer split the interval, else the loop never ends.
            if m <= lo || m >= hi {
                break;
            }
            if pred(m) == va {
                lo = m;
            } else {
                hi = m;
            }
        }
        let mut x = 0.5 * (lo + hi);
        if sa && x - a < SNAP_M {
            x = a;
        } else if sb && b - x < SNAP_M {
            x = b;
        }
        if va {
            if let Some(st) = start.take() {
                out.push([st, x]);
            }
        } else {
            start = Some(x);
        }
    }
    if let (Some(st), Some(last)) = (start, pts.last()) {
        out.push([st, last.0]);
    }
    out.retain(|[a, b]| b - a > 1e-9);
    out
}

fn sorted_unique(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    v
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Joins pieces end to start (in order, repeatedly).
fn chain(mut pieces: Vec<Vec<[f64; 2]>>) -> Vec<Vec<[f64; 2]>> {
    let mut merged = true;
    while merged {
        merged = false;
        'outer: for i in 0..pieces.len() {
            for j in 0..pieces.len() {
                if i == j {
                    continue;
                }
                let (Some(end), Some(start)) = (pieces[i].last(), pieces[j].first()) else {
                    continue;
                };
                if dist(*end, *start) <= CHAIN_M {
                    let tail = pieces.remove(j);
                    let i = if j < i { i - 1 } else { i };
                    pieces[i].extend_from_slice(&tail[1..]);
                    merged = true;
                    break 'outer;
                }
            }
        }
    }
    pieces
}

impl LaneRoad {
    /// Fills `outer_edges`, `edge_tree`, `dividers` and `lane_ends`.
    pub(crate) fn build_drivable_area(&mut self) {
        let mut pieces: Vec<Vec<[f64; 2]>> = Vec::new();
        let mut dividers = Vec::new();
        let mut lane_ends = Vec::new();
        for (i, l) in self.lanes.iter().enumerate() {
            let others = self.overlapping_lanes(i);
            // Where coverage of this lane's bounds may change.
            let mut samples: Vec<f64> = l.centreline.vertex_s_m().to_vec();
            for &j in &others {
                let o = &self.lanes[j];
                let ends = [o.point(0.0, 0.0), o.point(o.length_m(), 0.0)];
                for p in o
                    .bound_polyline(Side::Left)
                    .into_iter()
                    .chain(o.bound_polyline(Side::Right))
                    .chain(ends)
                {
                    let s = l.project(p).s_m;
                    if s > 0.0 && s < l.length_m() {
                        samples.push(s);
                    }
                }
            }
            let samples = sorted_unique(samples);
            let bound_piece = |side: Side, [a, b]: [f64; 2]| -> Vec<[f64; 2]> {
                let mut ss = vec![a];
                ss.extend(
                    l.centreline
                        .vertex_s_m()
                        .iter()
                        .copied()
                        .filter(|&s| s > a + 1e-9 && s < b - 1e-9),
                );
                ss.push(b);
                ss.iter()
                    .map(|&s| l.point(s, l.bound_d_m(side, s)))
                    .collect()
            };
            for side in [Side::Left, Side::Right] {
                let out = match side {
                    Side::Left => NUDGE_M,
                    Side::Right => -NUDGE_M,
                };
                let beyond = |s: f64| l.point(s, l.bound_d_m(side, s) + out);
                // Outer edge: nothing drivable just beyond the bound.
                let open = |s: f64| self.other_lane_at(beyond(s), i).is_none();
                for iv in true_intervals(&samples, &open) {
                    pieces.push(bound_piece(side, iv));
                }
                // Divider: the named neighbour lies just beyond (once per pair).
                let Some(nid) = l.neighbour(side) else {
                    continue;
                };
                let Some(&ni) = self.by_id.get(&nid) else {
                    continue;
                };
                let nb = &self.lanes[ni];
                let named_back = match side {
                    Side::Left => false,
                    Side::Right => nb.left == Some(l.id),
                };
                if named_back {
                    continue;
                }
                let covered = |s: f64| nb.contains(beyond(s));
                for iv in true_intervals(&samples, &covered) {
                    let (left_lane, right_lane) = match side {
                        Side::Left => (nid, l.id),
                        Side::Right => (l.id, nid),
                    };
                    dividers.push(Divider {
                        left_lane,
                        right_lane,
                        polyline_m: bound_piece(side, iv),
                        s_range_m: iv,
                    });
                }
            }
            // Ends and starts without links: closed if a lane goes on beside them.
            let len = l.length_m();
            let (r_end, l_end) = (l.right_d_m(len), l.left_d_m(len));
            if l.successors.is_empty() {
                let ahead = [
                    l.point(len + AHEAD_M, l_end + AHEAD_M),
                    l.point(len + AHEAD_M, r_end - AHEAD_M),
                ];
                let closed = ahead.iter().any(|p| self.other_lane_at(*p, i).is_some());
                if closed {
                    let open = |d: f64| self.other_lane_at(l.point(len + NUDGE_M, d), i).is_none();
                    let ds = [r_end, 0.5 * (r_end + l_end), l_end];
                    for [a, b] in true_intervals(&ds, &open) {
                        pieces.push(vec![l.point(len, a), l.point(len, b)]);
                    }
                }
                lane_ends.push(LaneEnd {
                    lane: l.id,
                    s_m: len,
                    closed,
                    edge_m: [l.point(len, r_end), l.point(len, l_end)],
                });
            }
            if l.predecessors.is_empty() {
                let (r0, l0) = (l.right_d_m(0.0), l.left_d_m(0.0));
                let behind = [
                    l.point(-AHEAD_M, l0 + AHEAD_M),
                    l.point(-AHEAD_M, r0 - AHEAD_M),
                ];
                if behind.iter().any(|p| self.other_lane_at(*p, i).is_some()) {
                    let open = |d: f64| self.other_lane_at(l.point(-NUDGE_M, d), i).is_none();
                    let ds = [r0, 0.5 * (r0 + l0), l0];
                    for [a, b] in true_intervals(&ds, &open) {
                        // Left to right, so that it chains with the bounds' direction.
                        pieces.push(vec![l.point(0.0, b), l.point(0.0, a)]);
                    }
                }
            }
        }
        let chained = chain(pieces);
        let o = self.origin_m;
        let mut segments = Vec::new();
        for (k, poly) in chained.iter().enumerate() {
            for w in poly.windows(2) {
                let a = [w[0][0] - o[0], w[0][1] - o[1]];
                let b = [w[1][0] - o[0], w[1][1] - o[1]];
                segments.push(GeomWithData::new(Line::new(a, b), k));
            }
        }
        self.edge_tree = RTree::bulk_load(segments);
        self.outer_edges = chained
            .into_iter()
            .map(|polyline_m| OuterEdge { polyline_m })
            .collect();
        self.dividers = dividers;
        self.lane_ends = lane_ends;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_end_for_samples_a_few_ulps_apart() {
        // Two samples 2 ulps apart far along a lane (as the A9 CommonRoad map gives): the
        // bisection used to loop for ever once the midpoint equalled an end.
        let a = 700.0_f64;
        let b = f64::from_bits(a.to_bits() + 2);
        let mid = f64::from_bits(a.to_bits() + 1);
        let out = true_intervals(&[0.0, a, b, 800.0], &|s| s >= mid);
        assert_eq!(out.len(), 1);
        assert!(
            out[0][0] >= a && out[0][0] <= b && out[0][1] == 800.0,
            "{out:?}"
        );
    }

    #[test]
    fn intervals_find_and_snap_transitions() {
        let samples = [0.0, 10.0, 20.0, 30.0];
        let iv = true_intervals(&samples, &|x| (12.5..=20.0 - 1e-5).contains(&x));
        assert_eq!(iv.len(), 1);
        assert!((iv[0][0] - 12.5).abs() < 1e-8, "{iv:?}");
        assert_eq!(iv[0][1], 20.0);
    }

    #[test]
    fn chain_joins_end_to_start() {
        let c = chain(vec![
            vec![[1.0, 0.0], [2.0, 0.0]],
            vec![[0.0, 0.0], [1.0, 0.0]],
            vec![[5.0, 5.0], [6.0, 5.0]],
        ]);
        assert_eq!(c.len(), 2);
        assert!(c.contains(&vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]));
    }
}
