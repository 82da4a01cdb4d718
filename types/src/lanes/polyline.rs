//! A lane's centreline: cleaning, arc length, the curvilinear (s, d) frame with its exact
//! projection, and the smoothed heading and curvature along s. See the module docs of
//! [`crate::lanes`] for the method and its error bounds.

use std::f64::consts::FRAC_PI_2;

use rstar::RTree;
use rstar::primitives::{GeomWithData, Line};

use super::error::LaneError;
use super::spec::LaneId;

/// Largest turn accepted at one centreline vertex (rad): more is a spike or a reversal.
pub const MAX_VERTEX_TURN_RAD: f64 = FRAC_PI_2;

/// Centrelines with at most this many segments are projected by solving every cell, without
/// walking the index (its heap allocation costs more than a few exact solves).
const LINEAR_SCAN_SEGMENTS: usize = 8;

/// Slack on the segment parameter t ∈ [0, 1] when a point sits exactly on a cell's border.
const T_SLACK: f64 = 1e-12;

type Segment = GeomWithData<Line<[f64; 2]>, usize>;

/// Where a point lies in a lane's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FramePoint {
    /// Arc length along the centreline (m); negative before its start, beyond its length after
    /// its end (the frame continues straight there).
    pub s_m: f64,
    /// Lateral offset (m), positive to the left of the direction of travel.
    pub d_m: f64,
}

/// The frame's axes at a point (for mapping gradients later): `p(s, d)` and its partial
/// derivatives. `dp_dd` is the frame's normal, not of unit length at a vertex (see the module
/// docs); `dp_ds` has unit length on the centreline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameAxes {
    /// The world point (m).
    pub point_m: [f64; 2],
    /// ∂p/∂s.
    pub dp_ds: [f64; 2],
    /// ∂p/∂d.
    pub dp_dd: [f64; 2],
}

/// A cleaned centreline with its frame.
#[derive(Clone, Debug)]
pub struct Centreline {
    /// Local origin: every stored position is relative to it (the first input vertex).
    origin_m: [f64; 2],
    /// Cleaned vertices, relative to `origin_m`.
    pts: Vec<[f64; 2]>,
    /// Arc length at each vertex.
    s_m: Vec<f64>,
    /// Unit direction of each segment.
    dir: Vec<[f64; 2]>,
    /// Length of each segment.
    len_m: Vec<f64>,
    /// Miter normal at each vertex: on the bisector, scaled so that its component along each
    /// adjacent segment's unit normal is 1 (offset curves are exact parallel polylines); at the
    /// two ends, the unit normal to the smoothed heading.
    miter: Vec<[f64; 2]>,
    /// Longest miter normal (≥ 1).
    max_miter: f64,
    /// Smoothed heading at each vertex (rad, unwrapped: continuous along the lane).
    heading_rad: Vec<f64>,
    /// Smoothed curvature at each vertex (1/m, positive turning left).
    curvature_1pm: Vec<f64>,
    /// Input index of each kept vertex.
    kept: Vec<usize>,
    /// Index of the segments (local coordinates).
    tree: RTree<Segment>,
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}
/// The unit normal to the left of a unit direction.
fn left_of(u: [f64; 2]) -> [f64; 2] {
    [-u[1], u[0]]
}

/// Indices of the input vertices kept by cleaning: a vertex within `tol_m` of the previous kept
/// vertex is dropped, except the last input vertex, which replaces the last kept one (so the
/// lane still ends where the data says).
pub fn clean_indices(raw: &[[f64; 2]], tol_m: f64) -> Vec<usize> {
    let mut kept: Vec<usize> = Vec::with_capacity(raw.len());
    for (i, p) in raw.iter().enumerate() {
        match kept.last() {
            None => kept.push(i),
            Some(&k) if norm(sub(*p, raw[k])) > tol_m => kept.push(i),
            Some(_) => {}
        }
    }
    let last = raw.len().saturating_sub(1);
    if raw.len() > 1 && kept.last() != Some(&last) && kept.len() > 1 {
        kept.pop();
        kept.push(last);
    }
    // The moved end may now sit within the tolerance of the vertex before it.
    while kept.len() > 2 {
        let n = kept.len();
        if norm(sub(raw[kept[n - 1]], raw[kept[n - 2]])) > tol_m {
            break;
        }
        kept.remove(n - 2);
    }
    kept
}

/// Mean of the piecewise-linear interpolant of `v` (knots `s`) over `[s_i - h_i, s_i + h_i]`,
/// `h_i = min(h, s_i, S - s_i)`, at every knot (the window shrinks at the ends so that it stays
/// symmetric: linear data is reproduced exactly).
fn window_mean(s: &[f64], v: &[f64], h: f64) -> Vec<f64> {
    let n = s.len();
    // Cumulative trapezoid integral at the knots.
    let mut integral = vec![0.0; n];
    for i in 1..n {
        integral[i] = integral[i - 1] + 0.5 * (v[i] + v[i - 1]) * (s[i] - s[i - 1]);
    }
    let total = s[n - 1];
    let eval = |x: f64| -> f64 {
        let k = s.partition_point(|&si| si <= x).clamp(1, n - 1) - 1;
        let ds = x - s[k];
        let slope = (v[k + 1] - v[k]) / (s[k + 1] - s[k]);
        integral[k] + v[k] * ds + 0.5 * slope * ds * ds
    };
    (0..n)
        .map(|i| {
            let hi = h.min(s[i]).min(total - s[i]);
            if hi <= 0.0 {
                v[i]
            } else {
                (eval(s[i] + hi) - eval(s[i] - hi)) / (2.0 * hi)
            }
        })
        .collect()
}

impl Centreline {
    /// Cleans `raw` (merge tolerance `merge_tol_m`), checks it, and builds the frame.
    /// `smoothing_half_window_m` > 0 averages the vertex headings and curvatures (module docs).
    pub fn new(
        lane: LaneId,
        raw: &[[f64; 2]],
        merge_tol_m: f64,
        smoothing_half_window_m: f64,
    ) -> Result<Self, LaneError> {
        const FIELD: &str = "centreline_m";
        for (index, p) in raw.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(LaneError::NonFinite {
                    lane,
                    field: FIELD,
                    index,
                });
            }
        }
        let kept = clean_indices(raw, merge_tol_m);
        if kept.len() < 2 {
            return Err(LaneError::TooFewVertices {
                lane,
                field: FIELD,
                distinct: kept.len(),
                tolerance_m: merge_tol_m,
            });
        }
        let origin_m = raw[0];
        let pts: Vec<[f64; 2]> = kept.iter().map(|&i| sub(raw[i], origin_m)).collect();
        let n = pts.len();
        let mut dir = Vec::with_capacity(n - 1);
        let mut len_m = Vec::with_capacity(n - 1);
        let mut s_m = Vec::with_capacity(n);
        s_m.push(0.0);
        for w in pts.windows(2) {
            let e = sub(w[1], w[0]);
            let l = norm(e);
            dir.push([e[0] / l, e[1] / l]);
            len_m.push(l);
            s_m.push(s_m[s_m.len() - 1] + l);
        }
        // Turns at the interior vertices, the miter normals, and the unwrapped segment headings.
        let mut seg_heading = Vec::with_capacity(n - 1);
        seg_heading.push(dir[0][1].atan2(dir[0][0]));
        let mut turn = vec![0.0; n];
        let mut miter = Vec::with_capacity(n);
        miter.push(left_of(dir[0]));
        let mut max_miter: f64 = 1.0;
        for i in 1..n - 1 {
            let (a, b) = (dir[i - 1], dir[i]);
            let t = cross(a, b).atan2(dot(a, b));
            if t.abs() > MAX_VERTEX_TURN_RAD {
                return Err(LaneError::SharpTurn {
                    lane,
                    field: FIELD,
                    index: kept[i],
                    turn_deg: t.to_degrees(),
                });
            }
            turn[i] = t;
            seg_heading.push(seg_heading[i - 1] + t);
            let (na, nb) = (left_of(a), left_of(b));
            let bis = [na[0] + nb[0], na[1] + nb[1]];
            // |t| ≤ 90°, so the bisector is far from zero and its component along na ≥ cos 45°.
            let scale = 1.0 / dot(bis, na);
            let m = [bis[0] * scale, bis[1] * scale];
            max_miter = max_miter.max(norm(m));
            miter.push(m);
        }
        miter.push(left_of(dir[n - 2]));

        // Vertex curvature: Menger (circle through the vertex and its two neighbours); heading:
        // that circle's tangent at the vertex. Exact for vertices sampled on a circle.
        let mut curvature_1pm = vec![0.0; n];
        for i in 1..n - 1 {
            let chord = norm(sub(pts[i + 1], pts[i - 1]));
            curvature_1pm[i] = 2.0 * turn[i].sin() / chord;
        }
        if n >= 3 {
            curvature_1pm[0] = curvature_1pm[1];
            curvature_1pm[n - 1] = curvature_1pm[n - 2];
        }
        let half_angle = |k: f64, l: f64| (0.5 * k * l).clamp(-1.0, 1.0).asin();
        let mut heading_rad = vec![0.0; n];
        heading_rad[0] = seg_heading[0] - half_angle(curvature_1pm[0], len_m[0]);
        for i in 1..n - 1 {
            let from_before = seg_heading[i - 1] + half_angle(curvature_1pm[i], len_m[i - 1]);
            let from_after = seg_heading[i] - half_angle(curvature_1pm[i], len_m[i]);
            heading_rad[i] = 0.5 * (from_before + from_after);
        }
        heading_rad[n - 1] = seg_heading[n - 2] + half_angle(curvature_1pm[n - 1], len_m[n - 2]);
        if smoothing_half_window_m > 0.0 {
            heading_rad = window_mean(&s_m, &heading_rad, smoothing_half_window_m);
            curvature_1pm = window_mean(&s_m, &curvature_1pm, smoothing_half_window_m);
        }
        // End normals: the unit normal to the smoothed heading (radial on an arc), so that lanes
        // starting or ending side by side share one cross-section and a lane's bounds meet its
        // successor's where their headings agree.
        for v in [0, n - 1] {
            miter[v] = [-heading_rad[v].sin(), heading_rad[v].cos()];
        }

        let segments: Vec<Segment> = (0..n - 1)
            .map(|i| GeomWithData::new(Line::new(pts[i], pts[i + 1]), i))
            .collect();
        Ok(Self {
            origin_m,
            pts,
            s_m,
            dir,
            len_m,
            miter,
            max_miter,
            heading_rad,
            curvature_1pm,
            kept,
            tree: RTree::bulk_load(segments),
        })
    }

    /// Length of the centreline (m).
    pub fn length_m(&self) -> f64 {
        self.s_m[self.s_m.len() - 1]
    }

    /// Number of vertices kept by cleaning.
    pub fn vertex_count(&self) -> usize {
        self.pts.len()
    }

    /// Input index of each kept vertex.
    pub fn kept_indices(&self) -> &[usize] {
        &self.kept
    }

    /// Arc length at each kept vertex (m).
    pub fn vertex_s_m(&self) -> &[f64] {
        &self.s_m
    }

    /// The kept vertices in world coordinates (m).
    pub fn vertices_m(&self) -> Vec<[f64; 2]> {
        self.pts.iter().map(|p| self.to_world(*p)).collect()
    }

    /// The local origin (m): stored positions are relative to it.
    pub fn origin_m(&self) -> [f64; 2] {
        self.origin_m
    }

    /// The largest length of the frame's normal (1 on straight lanes; 1/cos(turn/2) at a vertex).
    pub fn max_normal_length(&self) -> f64 {
        self.max_miter
    }

    fn to_world(&self, p: [f64; 2]) -> [f64; 2] {
        [p[0] + self.origin_m[0], p[1] + self.origin_m[1]]
    }

    /// The segment holding arc length `s_m` (clamped to the lane) and the parameter t there.
    fn locate(&self, s_m: f64) -> (usize, f64) {
        let nseg = self.len_m.len();
        let k = self.s_m.partition_point(|&si| si <= s_m).clamp(1, nseg) - 1;
        (k, (s_m - self.s_m[k]) / self.len_m[k])
    }

    /// Solves p − P(t) = d·N(t) on segment k (local coordinates): the roots t in [0, 1] and
    /// their d, the one with the smaller |d| first.
    fn solve_cell(&self, k: usize, q: [f64; 2]) -> Option<(f64, f64)> {
        let a = self.pts[k];
        let e = sub(self.pts[k + 1], a);
        let n0 = self.miter[k];
        let dn = sub(self.miter[k + 1], n0);
        let w = sub(q, a);
        // cross(w − tE, N0 + tD) = 0  ⇔  qa t² + qb t + qc = 0.
        let qa = -cross(e, dn);
        let qb = cross(w, dn) - cross(e, n0);
        let qc = cross(w, n0);
        let nrm = left_of(self.dir[k]);
        // N(t)·n_seg is 1 except on an end segment, whose end normal follows the heading.
        let d_at = |t: f64| {
            let nt = [n0[0] + t * dn[0], n0[1] + t * dn[1]];
            dot(sub(w, [t * e[0], t * e[1]]), nrm) / dot(nt, nrm)
        };
        let mut best: Option<(f64, f64)> = None;
        let mut consider = |t: f64| {
            if t.is_finite() && (-T_SLACK..=1.0 + T_SLACK).contains(&t) {
                let t = t.clamp(0.0, 1.0);
                let d = d_at(t);
                if best.is_none_or(|(_, bd)| d.abs() < bd.abs()) {
                    best = Some((t, d));
                }
            }
        };
        if qa.abs() <= 1e-14 * qb.abs() {
            consider(-qc / qb);
        } else {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                return None;
            }
            let root = -0.5 * (qb + qb.signum() * disc.sqrt());
            consider(root / qa);
            if root != 0.0 {
                consider(qc / root);
            }
        }
        best
    }

    /// Projects a world point into the frame: the (s, d) with p = [`Self::point`]`(s, d)`
    /// whose |d| is smallest. The spatial index gives the segments in order of distance; the
    /// exact solve runs on each until no farther segment can hold a smaller |d| (a cell whose
    /// |d| is δ lies within δ·max‖N‖ of its segment).
    pub fn project(&self, p_m: [f64; 2]) -> FramePoint {
        let q = sub(p_m, self.origin_m);
        let nseg = self.len_m.len();
        let mut best: Option<FramePoint> = None;
        fn keep(best: &mut Option<FramePoint>, fp: FramePoint) {
            if best.is_none_or(|b| fp.d_m.abs() < b.d_m.abs()) {
                *best = Some(fp);
            }
        }
        // Straight continuations before the start and after the end: p = P + s·u + d·N, so
        // s = cross(w, N) / cross(u, N) and d = cross(u, w) / cross(u, N).
        let w0 = sub(q, self.pts[0]);
        let (u0, m0) = (self.dir[0], self.miter[0]);
        let before = cross(w0, m0) / cross(u0, m0);
        if before < 0.0 {
            keep(
                &mut best,
                FramePoint {
                    s_m: before,
                    d_m: cross(u0, w0) / cross(u0, m0),
                },
            );
        }
        let wl = sub(q, self.pts[nseg]);
        let (ul, ml) = (self.dir[nseg - 1], self.miter[nseg]);
        let after = cross(wl, ml) / cross(ul, ml);
        if after > 0.0 {
            keep(
                &mut best,
                FramePoint {
                    s_m: self.length_m() + after,
                    d_m: cross(ul, wl) / cross(ul, ml),
                },
            );
        }
        if nseg <= LINEAR_SCAN_SEGMENTS {
            // A few segments: solve every cell (no index walk, no allocation).
            for k in 0..nseg {
                if let Some((t, d)) = self.solve_cell(k, q) {
                    keep(
                        &mut best,
                        FramePoint {
                            s_m: self.s_m[k] + t * self.len_m[k],
                            d_m: d,
                        },
                    );
                }
            }
        } else {
            self.project_indexed(q, &mut best, keep);
        }
        match best {
            Some(b) => b,
            None => {
                // Beyond the band where the frame is one-to-one (|d| of the order of the radius of
                // curvature or more): the foot on the nearest segment.
                let k = self
                    .tree
                    .nearest_neighbor(q)
                    .map(|seg| seg.data)
                    .unwrap_or(0);
                let w = sub(q, self.pts[k]);
                let t = (dot(w, self.dir[k]) / self.len_m[k]).clamp(0.0, 1.0);
                FramePoint {
                    s_m: self.s_m[k] + t * self.len_m[k],
                    d_m: dot(w, left_of(self.dir[k])),
                }
            }
        }
    }

    /// The index walk of [`Self::project`]: segments in order of distance, each solved exactly,
    /// until no farther segment can hold a smaller |d|.
    fn project_indexed(
        &self,
        q: [f64; 2],
        best: &mut Option<FramePoint>,
        keep: fn(&mut Option<FramePoint>, FramePoint),
    ) {
        for (seg, dist2) in self.tree.nearest_neighbor_iter_with_distance_2(q) {
            if let Some(b) = *best
                && dist2.sqrt() > b.d_m.abs() * self.max_miter * (1.0 + 1e-12) + 1e-12
            {
                break;
            }
            let k = seg.data;
            if let Some((t, d)) = self.solve_cell(k, q) {
                keep(
                    best,
                    FramePoint {
                        s_m: self.s_m[k] + t * self.len_m[k],
                        d_m: d,
                    },
                );
            }
        }
    }

    /// The world point at (s, d), with the frame's axes there.
    pub fn axes(&self, s_m: f64, d_m: f64) -> FrameAxes {
        let nseg = self.len_m.len();
        let (point, dp_ds, dp_dd) = if s_m < 0.0 {
            let (u, n) = (self.dir[0], self.miter[0]);
            let o = self.pts[0];
            (
                [
                    o[0] + s_m * u[0] + d_m * n[0],
                    o[1] + s_m * u[1] + d_m * n[1],
                ],
                u,
                n,
            )
        } else if s_m > self.length_m() {
            let (u, n) = (self.dir[nseg - 1], self.miter[nseg]);
            let o = self.pts[nseg];
            let ds = s_m - self.length_m();
            (
                [o[0] + ds * u[0] + d_m * n[0], o[1] + ds * u[1] + d_m * n[1]],
                u,
                n,
            )
        } else {
            let (k, t) = self.locate(s_m);
            let a = self.pts[k];
            let e = sub(self.pts[k + 1], a);
            let n0 = self.miter[k];
            let dn = sub(self.miter[k + 1], n0);
            let n = [n0[0] + t * dn[0], n0[1] + t * dn[1]];
            let l = self.len_m[k];
            (
                [a[0] + t * e[0] + d_m * n[0], a[1] + t * e[1] + d_m * n[1]],
                [(e[0] + d_m * dn[0]) / l, (e[1] + d_m * dn[1]) / l],
                n,
            )
        };
        FrameAxes {
            point_m: self.to_world(point),
            dp_ds,
            dp_dd,
        }
    }

    /// The world point at (s, d) (m): the inverse of [`Self::project`].
    pub fn point(&self, s_m: f64, d_m: f64) -> [f64; 2] {
        self.axes(s_m, d_m).point_m
    }

    /// Smoothed heading of the centreline at `s_m` (rad, unwrapped): a cubic Hermite through the
    /// vertex headings with the vertex curvatures as slopes, so it is C¹ in s. Beyond the ends,
    /// the end value.
    pub fn heading_rad(&self, s_m: f64) -> f64 {
        self.heading_and_curvature(s_m).0
    }

    /// Smoothed curvature at `s_m` (1/m, positive turning left): the derivative of
    /// [`Self::heading_rad`], continuous in s. Beyond the ends, the end value.
    pub fn curvature_1pm(&self, s_m: f64) -> f64 {
        self.heading_and_curvature(s_m).1
    }

    /// Heading (rad) and curvature (1/m) at `s_m`.
    pub fn heading_and_curvature(&self, s_m: f64) -> (f64, f64) {
        let s = s_m.clamp(0.0, self.length_m());
        let (k, u) = self.locate(s);
        let u = u.clamp(0.0, 1.0);
        let l = self.len_m[k];
        let (h0, h1) = (self.heading_rad[k], self.heading_rad[k + 1]);
        let (m0, m1) = (self.curvature_1pm[k] * l, self.curvature_1pm[k + 1] * l);
        let (u2, u3) = (u * u, u * u * u);
        let heading = (2.0 * u3 - 3.0 * u2 + 1.0) * h0
            + (u3 - 2.0 * u2 + u) * m0
            + (-2.0 * u3 + 3.0 * u2) * h1
            + (u3 - u2) * m1;
        let slope = (6.0 * u2 - 6.0 * u) * h0
            + (3.0 * u2 - 4.0 * u + 1.0) * m0
            + (-6.0 * u2 + 6.0 * u) * h1
            + (3.0 * u2 - 2.0 * u) * m1;
        (heading, slope / l)
    }

    /// Unit tangent of the smoothed heading at `s_m`.
    pub fn tangent(&self, s_m: f64) -> [f64; 2] {
        let h = self.heading_rad(s_m);
        [h.cos(), h.sin()]
    }

    /// Axis-aligned box of the vertices (world, m): `[min, max]`.
    pub fn bounding_box_m(&self) -> [[f64; 2]; 2] {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &self.pts {
            for i in 0..2 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        [self.to_world(lo), self.to_world(hi)]
    }

    /// [`Self::interpolate`] and its derivative along s (per metre; 0 beyond the ends, where the
    /// value is clamped). At a vertex, the slope of the segment that begins there.
    pub fn interpolate_with_slope(&self, values: &[f64], s_m: f64) -> (f64, f64) {
        let s = s_m.clamp(0.0, self.length_m());
        let (k, t) = self.locate(s);
        let t = t.clamp(0.0, 1.0);
        let dv = values[k + 1] - values[k];
        let slope = if s_m < 0.0 || s_m > self.length_m() {
            0.0
        } else {
            dv / self.len_m[k]
        };
        (values[k] + t * dv, slope)
    }

    /// Interpolates per-vertex values linearly in s (clamped to the end values beyond the ends).
    pub fn interpolate(&self, values: &[f64], s_m: f64) -> f64 {
        let s = s_m.clamp(0.0, self.length_m());
        let (k, t) = self.locate(s);
        let t = t.clamp(0.0, 1.0);
        values[k] + t * (values[k + 1] - values[k])
    }
}

#[cfg(test)]
mod tests;
