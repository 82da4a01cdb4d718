//! The input description of a road of lanes (serde): lanes as polylines with widths and links,
//! plus the tolerances used to clean and check them. [`LaneRoad::new`](super::LaneRoad::new)
//! turns it into the queryable road, or refuses it with a [`LaneError`](super::LaneError).

use std::fmt;

use serde::{Deserialize, Serialize};

/// Identifier of a lane (CommonRoad lanelet ids are integers too).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct LaneId(pub u32);

impl fmt::Display for LaneId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// What a lane is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LaneKind {
    /// A lane of the main carriageway (including one that ends in a lane drop).
    #[default]
    Main,
    /// An entry lane: on-ramp or acceleration lane.
    Entry,
    /// An exit lane: off-ramp or deceleration lane.
    Exit,
    /// A hard shoulder.
    Shoulder,
}

/// One lane as data: a centreline polyline, its widths and its links.
///
/// Widths come in one of two forms, each a list with one value (constant along the lane) or one
/// value per centreline vertex (linear in s in between):
/// - `width_m`: the lane is centred on its centreline;
/// - `left_width_m` and `right_width_m`: the distances from the centreline to the left and the
///   right bound (the right one may be negative, for a taper whose outer bound crosses the
///   centreline, as in the merge road's ending lane).
///
/// Links: `left` / `right` name the same-direction neighbour sharing that bound (over part of
/// the lane at least); `successors` / `predecessors` the lanes it flows into / from. A link given
/// on one side only is completed on the other (a successor link makes the predecessor link).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaneSpec {
    /// The lane's id (unique in the road).
    pub id: LaneId,
    /// What the lane is for.
    #[serde(default)]
    pub kind: LaneKind,
    /// Centreline vertices `[x, y]` (m) in the direction of travel.
    pub centreline_m: Vec<[f64; 2]>,
    /// Width of a centred lane (m): one value, or one per vertex.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub width_m: Vec<f64>,
    /// Distance from the centreline to the left bound (m): one value, or one per vertex.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_width_m: Vec<f64>,
    /// Distance from the centreline to the right bound (m, positive to the right).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub right_width_m: Vec<f64>,
    /// Same-direction neighbour on the left.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left: Option<LaneId>,
    /// Same-direction neighbour on the right.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right: Option<LaneId>,
    /// Lanes this lane flows into.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub successors: Vec<LaneId>,
    /// Lanes flowing into this lane (two for a Y-merge).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub predecessors: Vec<LaneId>,
}

impl LaneSpec {
    /// A centred main lane of constant width, without links.
    pub fn new(id: LaneId, centreline_m: Vec<[f64; 2]>, width_m: f64) -> Self {
        Self {
            id,
            kind: LaneKind::Main,
            centreline_m,
            width_m: vec![width_m],
            left_width_m: Vec::new(),
            right_width_m: Vec::new(),
            left: None,
            right: None,
            successors: Vec::new(),
            predecessors: Vec::new(),
        }
    }
}

/// Tolerances used to clean and check lane data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LaneTolerances {
    /// Centreline vertices closer than this to the previous kept vertex are merged into it (m).
    pub vertex_merge_m: f64,
    /// How far a successor's start may lie from a lane's end, and how far a neighbour's bound
    /// from the lane's bound (m).
    pub link_m: f64,
    /// Half-width of the moving average applied to the vertex headings and curvatures (m);
    /// 0 = none (exact for clean data). See the module docs for its bias.
    pub smoothing_half_window_m: f64,
}

impl Default for LaneTolerances {
    fn default() -> Self {
        Self {
            vertex_merge_m: 0.05,
            link_m: 0.1,
            smoothing_half_window_m: 0.0,
        }
    }
}

/// A road of lanes as data.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaneRoadSpec {
    /// The lanes.
    pub lanes: Vec<LaneSpec>,
    /// Cleaning and checking tolerances.
    #[serde(default)]
    pub tolerances: LaneTolerances,
}
