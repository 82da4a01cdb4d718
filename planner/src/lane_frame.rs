//! Mapping between a lane's curvilinear frame (s, d) and the world (x, y) for the planners:
//! world gradients of s and d (Eq. 7's mapping of the road terms' gradients), the heading
//! relative to the lane (Eq. 4 on a curved road) and the curvature of a path given in the frame,
//! road curvature included (Eq. 10a).
//!
//! The frame is [`Centreline::axes`]: p(s, d) with ∂p/∂s and ∂p/∂d. The world gradients of s and
//! d are the rows of the inverse Jacobian, ∇s = perp(∂p/∂d)/J and ∇d = −perp(∂p/∂s)/J with
//! J = ∂p/∂s × ∂p/∂d, so for a field U(s, d), ∇U = ∂U/∂s · ∇s + ∂U/∂d · ∇d. On the centreline
//! of a uniformly sampled arc, ∇s = t(s) and ∇d = n(s); at an offset d on a curve of curvature κ,
//! |∇s| = 1/(1 − κd); on a straight lane, ∇s = (1, 0) and ∇d = (0, 1) rotated with the lane.

use mergesim_types::lanes::{Centreline, FrameAxes, FramePoint};

/// A world point's place in a lane frame with the world gradients of s and d there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameJacobian {
    /// (s, d) of the point (m).
    pub frame: FramePoint,
    /// ∇s (world, 1).
    pub grad_s: [f64; 2],
    /// ∇d (world, 1).
    pub grad_d: [f64; 2],
}

/// ∇s and ∇d from the frame's axes (the inverse Jacobian's rows). A degenerate frame
/// (∂p/∂s ∥ ∂p/∂d: only at |d| ≥ the radius of curvature) gives zeros.
pub(crate) fn frame_gradients(axes: &FrameAxes) -> ([f64; 2], [f64; 2]) {
    let (ps, pd) = (axes.dp_ds, axes.dp_dd);
    let det = ps[0] * pd[1] - ps[1] * pd[0];
    if det.abs() <= f64::EPSILON || !det.is_finite() {
        return ([0.0, 0.0], [0.0, 0.0]);
    }
    ([pd[1] / det, -pd[0] / det], [-ps[1] / det, ps[0] / det])
}

/// Projects `p_m` into the frame and returns (s, d) with ∇s and ∇d there.
pub fn frame_jacobian(centreline: &Centreline, p_m: [f64; 2]) -> FrameJacobian {
    let frame = centreline.project(p_m);
    let axes = centreline.axes(frame.s_m, frame.d_m);
    let (grad_s, grad_d) = frame_gradients(&axes);
    FrameJacobian {
        frame,
        grad_s,
        grad_d,
    }
}

/// ∂U/∂s · ∇s + ∂U/∂d · ∇d: a frame gradient mapped to the world (Eq. 7 in the lane frame).
pub(crate) fn to_world_gradient(j: &FrameJacobian, du_ds: f64, du_dd: f64) -> [f64; 2] {
    [
        du_ds * j.grad_s[0] + du_dd * j.grad_d[0],
        du_ds * j.grad_s[1] + du_dd * j.grad_d[1],
    ]
}

/// A vehicle's heading relative to the lane at its position (rad, in [−π, π)): its world yaw
/// minus the lane's smoothed heading at the vehicle's s. Eq. 4's ψ_o on a curved road: a
/// vehicle following the lane has 0 here whatever the map's orientation, so a rotated map gives
/// the same obstacle field. On a straight road along +x it is the world yaw.
pub fn lane_relative_heading_rad(centreline: &Centreline, p_m: [f64; 2], yaw_rad: f64) -> f64 {
    let s = centreline.project(p_m).s_m;
    mergesim_types::angle::wrap_angle_rad(yaw_rad - centreline.heading_rad(s))
}

/// A path given in a lane frame as d(s), at one s: its offset and two derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FramePath {
    /// d at s (m).
    pub d_m: f64,
    /// dd/ds (1).
    pub dd_ds: f64,
    /// d²d/ds² (1/m).
    pub d2d_ds2_per_m: f64,
}

/// The world curvature of a path d(s) given in a lane frame
/// (1/m, positive turning left), Eq. 10a's κ with the road's curvature included.
///
/// With κ_r the lane's curvature at s, κ_r' = dκ_r/ds, q = 1 − κ_r d and Δθ = atan(d'/q) the
/// path's heading relative to the lane, the curvature of the world curve p(s, d(s)) is
/// κ = (κ_r + (d'' + (κ_r' d + κ_r d') tan Δθ) cos²Δθ / q) · cos Δθ / q
/// (the Frenet-frame relation of Werling et al., ICRA 2010). On a straight lane (κ_r = 0) it is
/// the plane curve's d''/(1 + d'²)^{3/2}; a path at constant offset d on an arc of radius R has
/// 1/(R − d). Returns NaN where q ≤ 0 (beyond the centre of curvature: no frame there).
/// `road_curvature_1pm` is κ_r and `road_curvature_rate_1pm2` dκ_r/ds at the path's s (1/m, 1/m²).
pub fn path_curvature_with_road_1pm(
    path: &FramePath,
    road_curvature_1pm: f64,
    road_curvature_rate_1pm2: f64,
) -> f64 {
    let (kr, dkr) = (road_curvature_1pm, road_curvature_rate_1pm2);
    let q = 1.0 - kr * path.d_m;
    if q <= 0.0 {
        return f64::NAN;
    }
    let tan_rel = path.dd_ds / q;
    let cos_rel = 1.0 / (1.0 + tan_rel * tan_rel).sqrt();
    (kr + (path.d2d_ds2_per_m + (dkr * path.d_m + kr * path.dd_ds) * tan_rel) * cos_rel * cos_rel
        / q)
        * cos_rel
        / q
}

/// [`path_curvature_with_road_1pm`] on a lane: κ_r from the centreline's smoothed curvature at
/// `s_m`, κ_r' by a central difference of it over ±`rate_step_m` (the smoothed curvature is
/// continuous and piecewise quadratic in s, so a step of a tenth of the vertex spacing is ample).
pub fn path_curvature_on_lane_1pm(
    centreline: &Centreline,
    s_m: f64,
    path: &FramePath,
    rate_step_m: f64,
) -> f64 {
    let kr = centreline.curvature_1pm(s_m);
    let h = rate_step_m.abs().max(1e-6);
    let dkr = (centreline.curvature_1pm(s_m + h) - centreline.curvature_1pm(s_m - h)) / (2.0 * h);
    path_curvature_with_road_1pm(path, kr, dkr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::MergeRoad;
    use mergesim_types::lanes::{LaneRoad, THROUGH_LANE_ID, curved_merge_spec};
    use std::f64::consts::PI;

    fn arc_road() -> LaneRoad {
        LaneRoad::new(&curved_merge_spec(&MergeRoad::default(), 300.0).unwrap()).unwrap()
    }

    #[test]
    fn gradients_of_s_and_d_match_finite_differences_on_the_arc() {
        let road = arc_road();
        let c = road.lane(THROUGH_LANE_ID).unwrap().centreline();
        let h = 1e-6;
        for (s, d) in [(30.3, 0.0), (100.7, 1.5), (250.2, -2.0), (400.5, 3.1)] {
            let p = c.point(s, d);
            let j = frame_jacobian(c, p);
            for (k, e) in [[h, 0.0], [0.0, h]].iter().enumerate() {
                let fp = c.project([p[0] + e[0], p[1] + e[1]]);
                let fm = c.project([p[0] - e[0], p[1] - e[1]]);
                let ds = (fp.s_m - fm.s_m) / (2.0 * h);
                let dd = (fp.d_m - fm.d_m) / (2.0 * h);
                assert!(
                    (ds - j.grad_s[k]).abs() < 1e-6,
                    "s {s} d {d}: {ds} vs {:?}",
                    j.grad_s
                );
                assert!(
                    (dd - j.grad_d[k]).abs() < 1e-6,
                    "s {s} d {d}: {dd} vs {:?}",
                    j.grad_d
                );
            }
            // |∇s| = 1/(1 − κd) on the arc (κ = 1/R of the through lane's centre, R = 300 − 1.75).
            let kappa = 1.0 / (300.0 - 1.75);
            let norm = j.grad_s[0].hypot(j.grad_s[1]);
            assert!((norm - 1.0 / (1.0 - kappa * d)).abs() < 1e-5, "{norm}");
        }
    }

    #[test]
    fn heading_relative_to_the_lane_is_zero_along_it() {
        let road = arc_road();
        let c = road.lane(THROUGH_LANE_ID).unwrap().centreline();
        for s in [10.0, 200.0, 500.0] {
            let p = c.point(s, 0.4);
            let h = c.heading_rad(s);
            assert!((lane_relative_heading_rad(c, p, h + 0.1) - 0.1).abs() < 1e-9);
            assert!((lane_relative_heading_rad(c, p, h - 3.0) + 3.0).abs() < 1e-9);
            assert!((lane_relative_heading_rad(c, p, h + 2.0 * PI) - 0.0).abs() < 1e-9);
        }
    }

    #[test]
    fn path_curvature_includes_the_road_curvature() {
        // Straight lane: the plane curve's curvature.
        let p = FramePath {
            d_m: 0.3,
            dd_ds: 0.2,
            d2d_ds2_per_m: 0.01,
        };
        let plane = 0.01 / (1.0_f64 + 0.04).powf(1.5);
        assert!((path_curvature_with_road_1pm(&p, 0.0, 0.0) - plane).abs() < 1e-15);
        // Constant offset on an arc of radius R: 1/(R − d).
        let r = 300.0;
        for d in [-3.0, 0.0, 2.5] {
            let p = FramePath {
                d_m: d,
                dd_ds: 0.0,
                d2d_ds2_per_m: 0.0,
            };
            let k = path_curvature_with_road_1pm(&p, 1.0 / r, 0.0);
            assert!((k - 1.0 / (r - d)).abs() < 1e-15, "{d}: {k}");
        }
        // A lane change on an arc of radius R (exact circle, centre at the origin, turning
        // left): against the world curve's curvature by finite differences of three points.
        let point = |s: f64, d: f64| {
            let phi = s / r;
            [(r - d) * phi.sin(), -(r - d) * phi.cos()]
        };
        let d_of = |s: f64| 1.0 * ((s - 100.0) / 40.0).tanh();
        let (s0, h) = (110.0, 0.05);
        let pts: Vec<[f64; 2]> = [s0 - h, s0, s0 + h]
            .iter()
            .map(|&s| point(s, d_of(s)))
            .collect();
        let menger = {
            let (a, b, cc) = (pts[0], pts[1], pts[2]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let bc = [cc[0] - b[0], cc[1] - b[1]];
            let ac = [cc[0] - a[0], cc[1] - a[1]];
            let cross = ab[0] * bc[1] - ab[1] * bc[0];
            2.0 * cross / (ab[0].hypot(ab[1]) * bc[0].hypot(bc[1]) * ac[0].hypot(ac[1]))
        };
        let e = 1e-3;
        let path = FramePath {
            d_m: d_of(s0),
            dd_ds: (d_of(s0 + e) - d_of(s0 - e)) / (2.0 * e),
            d2d_ds2_per_m: (d_of(s0 + e) - 2.0 * d_of(s0) + d_of(s0 - e)) / (e * e),
        };
        let k = path_curvature_with_road_1pm(&path, 1.0 / r, 0.0);
        assert!((k - menger).abs() < 1e-8, "{k} vs {menger}");
        // On the curved merge's polyline frame, κ_r from the smoothed curvature: the same to
        // the frame's own accuracy (κ of the through lane's centre: 1/(300 − 1.75)).
        let road = arc_road();
        let c = road.lane(THROUGH_LANE_ID).unwrap().centreline();
        let r_lane = 300.0 - 1.75;
        let on_lane = path_curvature_on_lane_1pm(c, s0, &path, 0.1);
        let exact = path_curvature_with_road_1pm(&path, 1.0 / r_lane, 0.0);
        assert!((on_lane - exact).abs() < 1e-8, "{on_lane} vs {exact}");
        assert!(
            (k - 1.0 / (r - path.d_m)).abs() > 1e-4,
            "the lane change shows"
        );
    }
}
