//! The typed refusal of inconsistent lane data: every variant names the lane and the field, so
//! a scenario loader can add the file and the line.

use thiserror::Error;

use super::spec::LaneId;

/// Lane data that cannot make a road.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LaneError {
    /// The road has no lanes at all.
    #[error("the road has no lanes (field lanes)")]
    NoLanes,
    /// Two lanes carry the same id.
    #[error("lane {lane}: id: used by two lanes")]
    DuplicateId {
        /// The repeated id.
        lane: LaneId,
    },
    /// A coordinate or width is NaN or infinite.
    #[error("lane {lane}: {field}[{index}] is not finite")]
    NonFinite {
        /// The lane.
        lane: LaneId,
        /// The field (`centreline_m`, `width_m`, ...).
        field: &'static str,
        /// Index of the offending entry.
        index: usize,
    },
    /// Fewer than two distinct vertices once near-duplicates are merged.
    #[error(
        "lane {lane}: {field}: {distinct} distinct vertices (at least 2 needed; vertices closer than {tolerance_m} m are merged)"
    )]
    TooFewVertices {
        /// The lane.
        lane: LaneId,
        /// Always `centreline_m`.
        field: &'static str,
        /// Distinct vertices found.
        distinct: usize,
        /// The merge tolerance used.
        tolerance_m: f64,
    },
    /// The centreline turns by more than 90° at one vertex (a spike or a reversal in the data).
    #[error(
        "lane {lane}: {field}[{index}]: the centreline turns by {turn_deg:.1}° there (at most 90°)"
    )]
    SharpTurn {
        /// The lane.
        lane: LaneId,
        /// Always `centreline_m`.
        field: &'static str,
        /// Index of the vertex in the input.
        index: usize,
        /// The turn (degrees).
        turn_deg: f64,
    },
    /// The widths are not given as one of the two accepted forms.
    #[error("lane {lane}: {field}: {reason}")]
    WidthFields {
        /// The lane.
        lane: LaneId,
        /// The field at fault.
        field: &'static str,
        /// What is expected.
        reason: String,
    },
    /// A width that is not positive (zero is allowed only at the first or last vertex, the tip
    /// of a taper).
    #[error(
        "lane {lane}: {field}[{index}]: width {width_m} m must be positive (0 is allowed only at the first or last vertex)"
    )]
    NonPositiveWidth {
        /// The lane.
        lane: LaneId,
        /// `width_m`, or `left_width_m`/`right_width_m` (their sum is the width).
        field: &'static str,
        /// Index of the vertex in the input.
        index: usize,
        /// The width there (m).
        width_m: f64,
    },
    /// A link names a lane the road does not have.
    #[error("lane {lane}: {field} names lane {target}, which does not exist")]
    UnknownLink {
        /// The lane.
        lane: LaneId,
        /// `left`, `right`, `successors` or `predecessors`.
        field: &'static str,
        /// The unknown id.
        target: LaneId,
    },
    /// A lane links to itself.
    #[error("lane {lane}: {field} names the lane itself")]
    SelfLink {
        /// The lane.
        lane: LaneId,
        /// The field at fault.
        field: &'static str,
    },
    /// A successor whose start does not meet its predecessor's end.
    #[error(
        "lane {lane}: {field}: lane {from} ends {gap_m:.3} m from the start of lane {to} (tolerance {tolerance_m} m)"
    )]
    LinkDoesNotMeet {
        /// The lane whose field holds the link.
        lane: LaneId,
        /// `successors` or `predecessors`.
        field: &'static str,
        /// The upstream lane.
        from: LaneId,
        /// The downstream lane.
        to: LaneId,
        /// How far the upstream lane's end (its centreline's last point) lies from the
        /// downstream lane's start cross-section (m).
        gap_m: f64,
        /// The tolerance (m).
        tolerance_m: f64,
    },
    /// A same-direction neighbour that does not share the lane's bound anywhere.
    #[error(
        "lane {lane}: {field}: lane {neighbour} is not beside this lane (its {other_side} bound meets this lane's {field} bound nowhere within {tolerance_m} m, in the same direction)"
    )]
    NeighbourNotBeside {
        /// The lane.
        lane: LaneId,
        /// `left` or `right`.
        field: &'static str,
        /// The claimed neighbour.
        neighbour: LaneId,
        /// The neighbour's side that should meet (`right` for a left neighbour).
        other_side: &'static str,
        /// The tolerance (m).
        tolerance_m: f64,
    },
    /// A tolerance out of range.
    #[error("tolerances.{field} = {value}: {reason}")]
    BadTolerance {
        /// The tolerance's field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range.
        reason: &'static str,
    },
}

impl LaneError {
    /// The lane at fault, if the error is about one lane.
    pub fn lane(&self) -> Option<LaneId> {
        match self {
            LaneError::NoLanes | LaneError::BadTolerance { .. } => None,
            LaneError::DuplicateId { lane }
            | LaneError::NonFinite { lane, .. }
            | LaneError::TooFewVertices { lane, .. }
            | LaneError::SharpTurn { lane, .. }
            | LaneError::WidthFields { lane, .. }
            | LaneError::NonPositiveWidth { lane, .. }
            | LaneError::UnknownLink { lane, .. }
            | LaneError::SelfLink { lane, .. }
            | LaneError::LinkDoesNotMeet { lane, .. }
            | LaneError::NeighbourNotBeside { lane, .. } => Some(*lane),
        }
    }

    /// The field at fault (`lanes`, `id`, `centreline_m`, `width_m`, `left`, `successors`, ...).
    pub fn field(&self) -> &'static str {
        match self {
            LaneError::NoLanes => "lanes",
            LaneError::DuplicateId { .. } => "id",
            LaneError::NonFinite { field, .. }
            | LaneError::TooFewVertices { field, .. }
            | LaneError::SharpTurn { field, .. }
            | LaneError::WidthFields { field, .. }
            | LaneError::NonPositiveWidth { field, .. }
            | LaneError::UnknownLink { field, .. }
            | LaneError::SelfLink { field, .. }
            | LaneError::LinkDoesNotMeet { field, .. }
            | LaneError::NeighbourNotBeside { field, .. }
            | LaneError::BadTolerance { field, .. } => field,
        }
    }
}
