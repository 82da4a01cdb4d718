//! The drivable area's outer edges prepared for the edge term of Eq. 3 on a road of lanes:
//! the signed Euclidean distance of a point to each edge polyline, positive on the drivable
//! side, with its gradient.
//!
//! - Each outer edge of [`LaneRoad::outer_edges`] is a chained polyline; its drivable side is
//!   found once, by testing a point 5 cm to its left at its longest segment's middle.
//! - An edge end lying at the road's open start or end (a bound's end where its lane has no
//!   predecessor, or ends open) is continued as a ray along its end segment, as the lane frame
//!   continues straight beyond a lane's ends: a planning horizon reaching past the road's end
//!   still sees the side edges (on the straight road, today's edges Y = const continue
//!   indefinitely too).
//! - The sign at a vertex is taken from the bisector of the two segments (the 2-D
//!   angle-weighted pseudo-normal), so the signed distance is continuous across vertices.
//! - Segments are grouped in blocks of [`BLOCK`] with a bounding box: the rays are tested
//!   first, then the nearest box, then only the boxes that could hold a nearer point.

use mergesim_types::lanes::{LaneRoad, Side};

/// Segments per bounding box.
const BLOCK: usize = 16;
/// How far to the left of an edge its drivable side is probed (m).
const SIDE_PROBE_M: f64 = 0.05;
/// An edge end within this of an open lane-bound end is continued as a ray (m).
const OPEN_END_M: f64 = 1e-6;

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn unit(a: [f64; 2]) -> [f64; 2] {
    let n = a[0].hypot(a[1]);
    if n > 0.0 {
        [a[0] / n, a[1] / n]
    } else {
        [0.0, 0.0]
    }
}

/// One outer edge, ready for distance queries (local coordinates).
#[derive(Clone, Debug)]
pub(crate) struct EdgeGeometry {
    /// Unit direction of each segment.
    dir: Vec<[f64; 2]>,
    /// The first segment continues backwards without end.
    ray_start: bool,
    /// The last segment continues forwards without end.
    ray_end: bool,
    /// +1 if the drivable area lies to the left of the edge's direction, −1 to its right.
    inside_sign: f64,
    /// Per block of segments: [min, max] corners of the box of its vertices (a ray's finite
    /// part only: the rays are always tested).
    boxes: Vec<[[f64; 2]; 2]>,
    /// Per segment, prepared for the foot-point search: start, edge vector, 1/|edge|² and the
    /// bounds of the foot parameter t (−∞ / +∞ on a ray).
    segs: Vec<Segment>,
    /// A single segment continued as a ray at both ends is a straight line: its point and
    /// unit normal towards the drivable side (the signed distance is then one dot product).
    line: Option<([f64; 2], [f64; 2])>,
}

/// One segment, prepared.
#[derive(Clone, Copy, Debug)]
struct Segment {
    a: [f64; 2],
    e: [f64; 2],
    inv_len2: f64,
    t_lo: f64,
    t_hi: f64,
}

/// The nearest point of an edge: signed clearance-side distance and its gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EdgeDistance {
    /// Distance to the edge, positive on its drivable side (m).
    pub distance_m: f64,
    /// ∇ of `distance_m` (unit length).
    pub gradient: [f64; 2],
}

/// The ends of the lanes' bounds that lie at the road's open start or end (world, m).
fn open_bound_ends(road: &LaneRoad) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for l in road.lanes() {
        let len = l.length_m();
        let at_start = l.predecessors().is_empty();
        let at_end = l.successors().is_empty() && road.lane_end(l.id()).is_some_and(|e| !e.closed);
        for side in [Side::Left, Side::Right] {
            if at_start {
                out.push(l.point(0.0, l.bound_d_m(side, 0.0)));
            }
            if at_end {
                out.push(l.point(len, l.bound_d_m(side, len)));
            }
        }
    }
    out
}

impl EdgeGeometry {
    /// Every outer edge of the road, relative to `origin_m`.
    pub(crate) fn all(road: &LaneRoad, origin_m: [f64; 2]) -> Vec<Self> {
        let open = open_bound_ends(road);
        let is_open = |p: [f64; 2]| {
            open.iter()
                .any(|q| (p[0] - q[0]).hypot(p[1] - q[1]) <= OPEN_END_M)
        };
        road.outer_edges()
            .iter()
            .filter_map(|e| {
                let mut pts: Vec<[f64; 2]> = Vec::with_capacity(e.polyline_m.len());
                for p in &e.polyline_m {
                    let q = sub(*p, origin_m);
                    if pts.last().is_none_or(|l| *l != q) {
                        pts.push(q);
                    }
                }
                if pts.len() < 2 {
                    return None;
                }
                let dir: Vec<[f64; 2]> = pts.windows(2).map(|w| unit(sub(w[1], w[0]))).collect();
                // Drivable side: probe beside the middle of the longest segment.
                let k = (0..dir.len())
                    .max_by(|&a, &b| {
                        let la = dot(sub(pts[a + 1], pts[a]), dir[a]);
                        let lb = dot(sub(pts[b + 1], pts[b]), dir[b]);
                        la.total_cmp(&lb)
                    })
                    .unwrap_or(0);
                let mid = [
                    0.5 * (pts[k][0] + pts[k + 1][0]) + origin_m[0],
                    0.5 * (pts[k][1] + pts[k + 1][1]) + origin_m[1],
                ];
                let left = [
                    mid[0] - SIDE_PROBE_M * dir[k][1],
                    mid[1] + SIDE_PROBE_M * dir[k][0],
                ];
                let inside_sign = if road.is_drivable(left) { 1.0 } else { -1.0 };
                let first = e.polyline_m[0];
                let last = e.polyline_m[e.polyline_m.len() - 1];
                let nseg = dir.len();
                let (ray_start, ray_end) = (is_open(first), is_open(last));
                let boxes = (0..nseg)
                    .step_by(BLOCK)
                    .map(|b0| {
                        let b1 = (b0 + BLOCK).min(nseg);
                        let mut lo = [f64::INFINITY; 2];
                        let mut hi = [f64::NEG_INFINITY; 2];
                        for p in &pts[b0..=b1] {
                            for i in 0..2 {
                                lo[i] = lo[i].min(p[i]);
                                hi[i] = hi[i].max(p[i]);
                            }
                        }
                        [lo, hi]
                    })
                    .collect();
                let segs = (0..nseg)
                    .map(|k| {
                        let a = pts[k];
                        let e = sub(pts[k + 1], a);
                        Segment {
                            a,
                            e,
                            inv_len2: 1.0 / dot(e, e),
                            t_lo: if ray_start && k == 0 {
                                f64::NEG_INFINITY
                            } else {
                                0.0
                            },
                            t_hi: if ray_end && k + 1 == nseg {
                                f64::INFINITY
                            } else {
                                1.0
                            },
                        }
                    })
                    .collect();
                let line = (nseg == 1 && ray_start && ray_end)
                    .then(|| (pts[0], [-inside_sign * dir[0][1], inside_sign * dir[0][0]]));
                Some(Self {
                    dir,
                    ray_start,
                    ray_end,
                    inside_sign,
                    boxes,
                    segs,
                    line,
                })
            })
            .collect()
    }

    /// Distance² from `q` (local) to segment k (with the rays), the foot point, and where the
    /// foot lies: -1 at the segment's start vertex, 1 at its end vertex, 0 inside.
    #[inline]
    fn segment(&self, k: usize, q: [f64; 2]) -> (f64, [f64; 2], i8) {
        let sg = &self.segs[k];
        let t = dot(sub(q, sg.a), sg.e) * sg.inv_len2;
        let (t, at) = if t <= sg.t_lo {
            (sg.t_lo, -1)
        } else if t >= sg.t_hi {
            (sg.t_hi, 1)
        } else {
            (t, 0)
        };
        let foot = [sg.a[0] + t * sg.e[0], sg.a[1] + t * sg.e[1]];
        let w = sub(q, foot);
        (dot(w, w), foot, at)
    }

    /// Signed distance (positive on the drivable side) from `q` (local) and its gradient.
    #[inline]
    pub(crate) fn distance(&self, q: [f64; 2]) -> EdgeDistance {
        if let Some((a, n)) = self.line {
            return EdgeDistance {
                distance_m: dot(sub(q, a), n),
                gradient: n,
            };
        }
        let nseg = self.segs.len();
        let mut best = (f64::INFINITY, [0.0, 0.0], 0_i8, 0_usize);
        if self.boxes.len() <= 1 {
            // One block (every edge of a straight road): test each segment, rays included.
            for k in 0..nseg {
                let (d2, foot, at) = self.segment(k, q);
                if d2 < best.0 {
                    best = (d2, foot, at, k);
                }
            }
            return self.signed(q, best);
        }
        let box_d2 = |b: &[[f64; 2]; 2]| {
            let dx = (b[0][0] - q[0]).max(0.0).max(q[0] - b[1][0]);
            let dy = (b[0][1] - q[1]).max(0.0).max(q[1] - b[1][1]);
            dx * dx + dy * dy
        };
        let scan = |bi: usize, best: &mut (f64, [f64; 2], i8, usize)| {
            let b0 = bi * BLOCK;
            for k in b0..(b0 + BLOCK).min(nseg) {
                let (d2, foot, at) = self.segment(k, q);
                if d2 < best.0 {
                    *best = (d2, foot, at, k);
                }
            }
        };
        // The rays first (the boxes hold only the finite segments), then the nearest box, then
        // every other box that could hold a nearer point.
        for k in [
            self.ray_start.then_some(0),
            self.ray_end.then_some(nseg - 1),
        ]
        .into_iter()
        .flatten()
        {
            let (d2, foot, at) = self.segment(k, q);
            if d2 < best.0 {
                best = (d2, foot, at, k);
            }
        }
        let first = (0..self.boxes.len())
            .min_by(|&a, &b| box_d2(&self.boxes[a]).total_cmp(&box_d2(&self.boxes[b])))
            .unwrap_or(0);
        scan(first, &mut best);
        for bi in 0..self.boxes.len() {
            if bi != first && box_d2(&self.boxes[bi]) <= best.0 {
                scan(bi, &mut best);
            }
        }
        self.signed(q, best)
    }

    /// The signed distance and its gradient from the nearest foot point found.
    #[inline]
    fn signed(&self, q: [f64; 2], best: (f64, [f64; 2], i8, usize)) -> EdgeDistance {
        let nseg = self.segs.len();
        let (d2, foot, at, k) = best;
        let dist = d2.sqrt();
        // Side: the segment's normal inside it (or on a ray); the bisector at a vertex.
        let tangent = match at {
            -1 if k > 0 => [
                self.dir[k - 1][0] + self.dir[k][0],
                self.dir[k - 1][1] + self.dir[k][1],
            ],
            1 if k + 1 < nseg => [
                self.dir[k][0] + self.dir[k + 1][0],
                self.dir[k][1] + self.dir[k + 1][1],
            ],
            _ => self.dir[k],
        };
        let w = sub(q, foot);
        let left = cross(tangent, w) >= 0.0;
        let sign = if left {
            self.inside_sign
        } else {
            -self.inside_sign
        };
        let gradient = if dist > 0.0 {
            let k = sign / dist;
            [k * w[0], k * w[1]]
        } else {
            // On the edge: the inward normal of its segment.
            let n = [-self.dir[k][1], self.dir[k][0]];
            [self.inside_sign * n[0], self.inside_sign * n[1]]
        };
        EdgeDistance {
            distance_m: sign * dist,
            gradient,
        }
    }
}
