//! Each lane's frame prepared for the many evaluations of one planning cycle (Eq. 7 steps the
//! local path through ≥ 160 points a cycle).
//!
//! - A lane whose centreline is a straight line (every vertex within [`STRAIGHT_TOL_M`] of the
//!   line through its end vertices, in order along it) is projected in O(1):
//!   s = (p − p_0)·t, d = (p − p_0)·n, ∇s = t, ∇d = n. That is what
//!   [`Centreline::project`] and [`Centreline::axes`] give on such a lane (the frame of a straight
//!   polyline is the Cartesian frame of its line), without the index walk.
//! - Any other lane goes through [`Centreline::project`] and [`Centreline::axes`].
//! - A bound whose offset d is the same at every vertex is stored as that constant
//!   (slope 0), so Eq. 2 on a constant-width lane needs no interpolation.

use mergesim_types::lanes::{Centreline, FramePoint, Lane, Side};

use crate::lane_frame::{FrameJacobian, frame_gradients};

/// A centreline counts as straight if every vertex lies within this of the line through its end
/// vertices (m).
pub(crate) const STRAIGHT_TOL_M: f64 = 1e-9;

/// One lane's frame, prepared.
#[derive(Clone, Debug)]
pub(crate) enum FastFrame {
    /// A straight centreline: its first vertex, unit tangent and left normal.
    Straight {
        origin_m: [f64; 2],
        tangent: [f64; 2],
        normal: [f64; 2],
    },
    /// Any other centreline: the general projection.
    General,
}

impl FastFrame {
    /// The frame of `c`.
    pub(crate) fn of(c: &Centreline) -> Self {
        let v = c.vertices_m();
        let (Some(&a), Some(&b)) = (v.first(), v.last()) else {
            return Self::General;
        };
        let e = [b[0] - a[0], b[1] - a[1]];
        let len = e[0].hypot(e[1]);
        if len.is_nan() || len <= 0.0 {
            return Self::General;
        }
        let t = [e[0] / len, e[1] / len];
        let n = [-t[1], t[0]];
        let mut last_along = f64::NEG_INFINITY;
        for p in &v {
            let w = [p[0] - a[0], p[1] - a[1]];
            let along = w[0] * t[0] + w[1] * t[1];
            let across = w[0] * n[0] + w[1] * n[1];
            if across.abs() > STRAIGHT_TOL_M || along < last_along {
                return Self::General;
            }
            last_along = along;
        }
        Self::Straight {
            origin_m: a,
            tangent: t,
            normal: n,
        }
    }

    /// (s, d) of `p_m` with ∇s and ∇d there.
    #[inline]
    pub(crate) fn jacobian(&self, c: &Centreline, p_m: [f64; 2]) -> FrameJacobian {
        match self {
            Self::Straight {
                origin_m,
                tangent,
                normal,
            } => {
                let w = [p_m[0] - origin_m[0], p_m[1] - origin_m[1]];
                FrameJacobian {
                    frame: FramePoint {
                        s_m: w[0] * tangent[0] + w[1] * tangent[1],
                        d_m: w[0] * normal[0] + w[1] * normal[1],
                    },
                    grad_s: *tangent,
                    grad_d: *normal,
                }
            }
            Self::General => {
                let frame = c.project(p_m);
                let axes = c.axes(frame.s_m, frame.d_m);
                let (grad_s, grad_d) = frame_gradients(&axes);
                FrameJacobian {
                    frame,
                    grad_s,
                    grad_d,
                }
            }
        }
    }

    /// (s, d) of `p_m` only.
    #[inline]
    pub(crate) fn project(&self, c: &Centreline, p_m: [f64; 2]) -> FramePoint {
        match self {
            Self::Straight {
                origin_m,
                tangent,
                normal,
            } => {
                let w = [p_m[0] - origin_m[0], p_m[1] - origin_m[1]];
                FramePoint {
                    s_m: w[0] * tangent[0] + w[1] * tangent[1],
                    d_m: w[0] * normal[0] + w[1] * normal[1],
                }
            }
            Self::General => c.project(p_m),
        }
    }
}

/// A lane bound's offset d_div(s), prepared: a constant, or the lane's interpolation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum BoundOffset {
    /// The same offset at every vertex (m).
    Constant(f64),
    /// Interpolated along the lane ([`Lane::bound_d_and_slope`]).
    Varying,
}

impl BoundOffset {
    /// The bound `side` of `lane`.
    pub(crate) fn of(lane: &Lane, side: Side) -> Self {
        let s = lane.centreline().vertex_s_m();
        let Some(&s0) = s.first() else {
            return Self::Varying;
        };
        let d0 = lane.bound_d_m(side, s0);
        if s.iter().all(|&si| lane.bound_d_m(side, si) == d0) {
            Self::Constant(d0)
        } else {
            Self::Varying
        }
    }

    /// d_div(s) and its slope.
    #[inline]
    pub(crate) fn at(&self, lane: &Lane, side: Side, s_m: f64) -> (f64, f64) {
        match self {
            Self::Constant(d) => (*d, 0.0),
            Self::Varying => lane.bound_d_and_slope(side, s_m),
        }
    }
}
