//! Roads made of lanes: each lane a centreline with its curvilinear frame, two bounds, a kind
//! and links; the road's drivable area is the union of its lanes.
//!
//! # The lane frame: s, d, heading, curvature
//! - **s** (m) is the arc length along the lane's cleaned centreline polyline, 0 at its first
//!   vertex, [`Centreline::length_m`] at its last. Before the start and after the end the frame
//!   continues straight along the end segments (s < 0, s > length).
//! - **d** (m) is the lateral offset, **positive to the left** of the direction of travel.
//!   A point is p(s, d) = P(t) + d·N(t) on the segment holding s, with P(t) the centreline
//!   point and N(t) the linear interpolation of the vertex normals. The interior vertex normals
//!   are *miter* normals: on the bisector of the two segments, scaled so that their component
//!   along each segment's unit normal is 1. So the curve d = const is the exact parallel (offset)
//!   polyline at distance |d|, d equals the perpendicular distance to the segment's line (on the
//!   end segments to within a relative 1 − cos(half the end segment's turn): the two end
//!   normals are the unit normals of the smoothed heading, radial on an arc, so lanes side by
//!   side start and end on one cross-section and a lane's bounds meet its successor's), and
//!   the frame has no gaps or overlaps at vertices as long as |d| stays below the local radius
//!   of curvature. [`Centreline::project`] inverts p(s, d) exactly (a quadratic in t per
//!   segment), so point → (s, d) → point round-trips to rounding error.
//! - **heading** (rad, unwrapped, counter-clockwise from +x) and **curvature** (1/m, positive
//!   turning left) are smoothed fields along s, not the polyline's piecewise-constant segment
//!   directions. At each vertex, the curvature is the Menger curvature of the vertex and its two
//!   neighbours (the circle through them) and the heading that circle's tangent there (at the
//!   end vertices, the neighbouring circle's). Between vertices the heading is the cubic
//!   Hermite with those headings and curvatures as values and slopes, and the curvature is its
//!   derivative: the heading is C¹ and the curvature continuous in s, so nothing jumps at a
//!   vertex. Error bound: for vertices sampled on a circle of radius R with chords ≤ c, vertex
//!   curvatures and headings are exact, and between vertices the curvature is within a
//!   relative c²/(16R²) + O(c⁴/R⁴) of 1/R (the Hermite slopes 2·sin(Δφ/2) versus the central
//!   angle Δφ ≈ c/R: the error is 6u(1−u)·Δφ²/24 at u along the chord); c = 1 m, R = 150 m:
//!   2.8e-6 (tests `arc_heading_and_curvature_match_the_circle`, `random_arcs_round_trip`).
//!   Add the data's own rounding: vertices carrying an error δ (an ulp of their coordinates,
//!   1.8e-12 m at 10 km) give a relative curvature error of order 2δ·R/c², so arcs sampled far
//!   more finely than their radius needs lose curvature digits far from the origin.
//!   The frame's own normal N(t) follows the
//!   bisectors, so it can differ from the smoothed heading's normal by at most half the turn at
//!   a vertex (0 for uniformly sampled arcs).
//!
//! # Cleaning and smoothing
//! Centrelines from data can repeat vertices. A vertex within
//! [`LaneTolerances::vertex_merge_m`] (default 5 cm) of the previous kept vertex is dropped; the
//! last input vertex is always kept (it replaces the last kept vertex if they are that close),
//! so the lane ends where the data says. Widths given per vertex follow their vertex. After
//! cleaning, a turn of more than 90° at a vertex is refused (a spike or a reversal). Noisy data
//! can be smoothed further with [`LaneTolerances::smoothing_half_window_m`] = h > 0: every vertex
//! heading and curvature is replaced by the mean of its piecewise-linear interpolant over
//! [s − h', s + h'], h' = min(h, s, length − s) (symmetric, so linear data is kept exactly; the
//! bias is at most h²·max|f''|/6 for the smoothed field f). Default 0.
//!
//! # Precision far from the origin
//! Each centreline stores its vertices relative to its own first vertex (and the road's outer
//! edges relative to the first lane's), so the projection's arithmetic runs on small numbers; a
//! query point is shifted once. A road 5.9 km from the origin projects as accurately as one at
//! the origin (test `far_from_origin_projects_as_accurately`).
//!
//! # Lookup
//! Each centreline indexes its segments in an R*-tree (`rstar`): a projection takes the segments
//! in order of distance and solves each exactly, stopping once no farther segment can hold a
//! smaller |d| (a cell with offset δ lies within δ·max|N| of its segment), so it is O(log n) in
//! the number of vertices. A centreline of at most 8 segments skips the index and solves every
//! cell (the same answer, without the index walk's allocation: 4× faster on a straight lane).
//! The road indexes its lanes' boxes, and its outer edges.
//!
//! # Drivable area
//! The drivable area is the union of the lanes. A bound shared with a neighbouring lane, or
//! lying inside another lane, is not a wall: [`LaneRoad::outer_edges`] keeps only the stretches
//! of bounds with nothing drivable just beyond them (see `drivable.rs` for the method), plus the
//! edge across the end of a lane that ends while a neighbour goes on ([`LaneEnd::closed`]). The
//! road's own start and end stay open. Gaps between lanes narrower than [`SLIVER_M`] (5 mm) are
//! closed: polylines sampling one curve at different vertices differ by a chord's sagitta.
//! [`LaneRoad::dividers`] are the bounds between
//! same-direction neighbours (Eq. 2), [`LaneRoad::signed_distance_to_edge_m`] the distance to
//! the outer edges, positive on the road (Eq. 3).
//!
//! # Links
//! A lane that ends is explicit: it has no successor while a neighbour goes on, or it joins
//! another lane through a successor link (a lane with two predecessors is a Y-merge). Links
//! are checked when the road is built ([`LaneError`] names the lane and the field).

mod builders;
mod drivable;
mod error;
mod lane;
mod lane_road;
mod polyline;
mod spec;

pub use builders::{
    ARC_STEP_M, CURVED_MERGE_RADIUS_M, ENDING_LANE_ID, ON_RAMP_BOUNDS, OnRampParams,
    THROUGH_LANE_ID, curved_merge_spec, merge_road_spec, on_ramp_ids, on_ramp_spec,
};
pub use error::LaneError;
pub use lane::{Lane, Side};
pub use lane_road::{Divider, LaneEnd, LaneHit, LaneRoad, OuterEdge, SLIVER_M};
pub use polyline::{Centreline, FrameAxes, FramePoint, MAX_VERTEX_TURN_RAD, clean_indices};
pub use spec::{LaneId, LaneKind, LaneRoadSpec, LaneSpec, LaneTolerances};
