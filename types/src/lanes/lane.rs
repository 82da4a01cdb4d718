//! One lane of a [`LaneRoad`](super::LaneRoad): its centreline frame, its bounds as lateral
//! offsets along s, its kind and its links.

use super::error::LaneError;
use super::polyline::{Centreline, FramePoint};
use super::spec::{LaneId, LaneKind, LaneSpec, LaneTolerances};

/// Which side of a lane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The left bound (d > 0 side).
    Left,
    /// The right bound.
    Right,
}

/// A lane, checked and indexed.
#[derive(Clone, Debug)]
pub struct Lane {
    pub(crate) id: LaneId,
    pub(crate) kind: LaneKind,
    pub(crate) centreline: Centreline,
    /// Lateral offset of the left bound at each kept vertex (m, d of the bound).
    pub(crate) left_d_m: Vec<f64>,
    /// Lateral offset of the right bound at each kept vertex (m, ≤ left).
    pub(crate) right_d_m: Vec<f64>,
    pub(crate) left: Option<LaneId>,
    pub(crate) right: Option<LaneId>,
    pub(crate) successors: Vec<LaneId>,
    pub(crate) predecessors: Vec<LaneId>,
}

/// Expands a width list (one value, or one per input vertex) to one value per input vertex.
fn per_vertex(
    lane: LaneId,
    field: &'static str,
    values: &[f64],
    n: usize,
) -> Result<Vec<f64>, LaneError> {
    for (index, v) in values.iter().enumerate() {
        if !v.is_finite() {
            return Err(LaneError::NonFinite { lane, field, index });
        }
    }
    match values.len() {
        1 => Ok(vec![values[0]; n]),
        len if len == n => Ok(values.to_vec()),
        len => Err(LaneError::WidthFields {
            lane,
            field,
            reason: format!("{len} values: give one, or one per centreline vertex ({n})"),
        }),
    }
}

impl Lane {
    /// Builds a lane from its description (links are checked by the road).
    pub(crate) fn new(spec: &LaneSpec, tol: &LaneTolerances) -> Result<Self, LaneError> {
        let lane = spec.id;
        let n = spec.centreline_m.len();
        let (left_w, right_w, field) = match (
            spec.width_m.is_empty(),
            spec.left_width_m.is_empty(),
            spec.right_width_m.is_empty(),
        ) {
            (false, true, true) => {
                let w = per_vertex(lane, "width_m", &spec.width_m, n)?;
                let half: Vec<f64> = w.iter().map(|x| 0.5 * x).collect();
                (half.clone(), half, "width_m")
            }
            (true, false, false) => (
                per_vertex(lane, "left_width_m", &spec.left_width_m, n)?,
                per_vertex(lane, "right_width_m", &spec.right_width_m, n)?,
                "left_width_m",
            ),
            (true, true, true) => {
                return Err(LaneError::WidthFields {
                    lane,
                    field: "width_m",
                    reason: "missing: give width_m, or both left_width_m and right_width_m".into(),
                });
            }
            (false, _, _) => {
                return Err(LaneError::WidthFields {
                    lane,
                    field: "width_m",
                    reason: "give width_m alone, or left_width_m and right_width_m instead".into(),
                });
            }
            (true, false, true) => {
                return Err(LaneError::WidthFields {
                    lane,
                    field: "right_width_m",
                    reason: "missing (left_width_m is given)".into(),
                });
            }
            (true, true, false) => {
                return Err(LaneError::WidthFields {
                    lane,
                    field: "left_width_m",
                    reason: "missing (right_width_m is given)".into(),
                });
            }
        };
        for index in 0..n {
            let width_m = left_w[index] + right_w[index];
            let tip = index == 0 || index + 1 == n;
            if width_m < 0.0 || (width_m == 0.0 && !tip) {
                return Err(LaneError::NonPositiveWidth {
                    lane,
                    field,
                    index,
                    width_m,
                });
            }
        }
        let centreline = Centreline::new(
            lane,
            &spec.centreline_m,
            tol.vertex_merge_m,
            tol.smoothing_half_window_m,
        )?;
        let kept = centreline.kept_indices();
        let left_d_m: Vec<f64> = kept.iter().map(|&i| left_w[i]).collect();
        let right_d_m: Vec<f64> = kept.iter().map(|&i| -right_w[i]).collect();
        if left_d_m.iter().zip(&right_d_m).all(|(l, r)| l - r <= 0.0) {
            return Err(LaneError::NonPositiveWidth {
                lane,
                field,
                index: 0,
                width_m: 0.0,
            });
        }
        Ok(Self {
            id: lane,
            kind: spec.kind,
            centreline,
            left_d_m,
            right_d_m,
            left: spec.left,
            right: spec.right,
            successors: spec.successors.clone(),
            predecessors: spec.predecessors.clone(),
        })
    }

    /// The lane's id.
    pub fn id(&self) -> LaneId {
        self.id
    }

    /// What the lane is for.
    pub fn kind(&self) -> LaneKind {
        self.kind
    }

    /// The centreline and its frame.
    pub fn centreline(&self) -> &Centreline {
        &self.centreline
    }

    /// Length of the lane along its centreline (m).
    pub fn length_m(&self) -> f64 {
        self.centreline.length_m()
    }

    /// Same-direction neighbour on the left.
    pub fn left_neighbour(&self) -> Option<LaneId> {
        self.left
    }

    /// Same-direction neighbour on the right.
    pub fn right_neighbour(&self) -> Option<LaneId> {
        self.right
    }

    /// The neighbour on one side.
    pub fn neighbour(&self, side: Side) -> Option<LaneId> {
        match side {
            Side::Left => self.left,
            Side::Right => self.right,
        }
    }

    /// Lanes this lane flows into (empty: the lane ends, or the road does).
    pub fn successors(&self) -> &[LaneId] {
        &self.successors
    }

    /// Lanes flowing into this one.
    pub fn predecessors(&self) -> &[LaneId] {
        &self.predecessors
    }

    /// Projects a world point into the lane's frame.
    pub fn project(&self, p_m: [f64; 2]) -> FramePoint {
        self.centreline.project(p_m)
    }

    /// The world point at (s, d).
    pub fn point(&self, s_m: f64, d_m: f64) -> [f64; 2] {
        self.centreline.point(s_m, d_m)
    }

    /// Smoothed heading at s (rad).
    pub fn heading_rad(&self, s_m: f64) -> f64 {
        self.centreline.heading_rad(s_m)
    }

    /// Smoothed curvature at s (1/m, positive turning left).
    pub fn curvature_1pm(&self, s_m: f64) -> f64 {
        self.centreline.curvature_1pm(s_m)
    }

    /// Lateral offset d of the left bound at s (m); linear in s between vertices.
    pub fn left_d_m(&self, s_m: f64) -> f64 {
        self.centreline.interpolate(&self.left_d_m, s_m)
    }

    /// Lateral offset d of the right bound at s (m).
    pub fn right_d_m(&self, s_m: f64) -> f64 {
        self.centreline.interpolate(&self.right_d_m, s_m)
    }

    /// Lateral offset of one bound at s (m).
    pub fn bound_d_m(&self, side: Side, s_m: f64) -> f64 {
        match side {
            Side::Left => self.left_d_m(s_m),
            Side::Right => self.right_d_m(s_m),
        }
    }

    /// Lateral offset of one bound at s and its slope d(d)/ds (m, per m; slope 0 beyond the
    /// lane's ends, where the offset keeps its end value). For the lane-frame road terms'
    /// ∂/∂s (Eqs. 2–3).
    pub fn bound_d_and_slope(&self, side: Side, s_m: f64) -> (f64, f64) {
        let offsets = match side {
            Side::Left => &self.left_d_m,
            Side::Right => &self.right_d_m,
        };
        self.centreline.interpolate_with_slope(offsets, s_m)
    }

    /// Width at s (m).
    pub fn width_m(&self, s_m: f64) -> f64 {
        self.left_d_m(s_m) - self.right_d_m(s_m)
    }

    /// A bound as a polyline (world, m): its points at the kept centreline vertices.
    pub fn bound_polyline(&self, side: Side) -> Vec<[f64; 2]> {
        let offsets = match side {
            Side::Left => &self.left_d_m,
            Side::Right => &self.right_d_m,
        };
        self.centreline
            .vertex_s_m()
            .iter()
            .zip(offsets)
            .map(|(s, d)| self.centreline.point(*s, *d))
            .collect()
    }

    /// True if (s, d) lies in the lane (bounds included).
    pub fn contains_frame(&self, fp: FramePoint) -> bool {
        fp.s_m >= 0.0
            && fp.s_m <= self.length_m()
            && fp.d_m <= self.left_d_m(fp.s_m)
            && fp.d_m >= self.right_d_m(fp.s_m)
    }

    /// True if the world point lies in the lane (bounds included).
    pub fn contains(&self, p_m: [f64; 2]) -> bool {
        self.contains_frame(self.project(p_m))
    }

    /// How far (s, d) lies outside the lane, measured in the frame (0 inside): the larger of the
    /// lateral excess beyond a bound and the longitudinal excess beyond an end (m).
    pub fn frame_excess_m(&self, fp: FramePoint) -> f64 {
        let lateral = (fp.d_m - self.left_d_m(fp.s_m)).max(self.right_d_m(fp.s_m) - fp.d_m);
        let longitudinal = (-fp.s_m).max(fp.s_m - self.length_m());
        lateral.max(longitudinal).max(0.0)
    }
}
