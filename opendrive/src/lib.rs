//! A road's geometry from an OpenDRIVE (`.xodr`) file, as mergesim's road of lanes.
//!
//! The `xodr` crate reads the file (any OpenDRIVE version: reference lines made of lines, arcs,
//! spirals, cubic polynomials, lane sections with width polynomials, road and junction links)
//! and bakes every lane into a centreline polyline with per-vertex widths and a lane graph.
//! This crate turns its **drivable** lanes (`driving`, `entry`, `exit`, `onRamp`, `offRamp`,
//! `connectingRamp`, `slipLane`, `bidirectional`, `bus`, `taxi`, `hov`, `shared`) into a
//! [`LaneRoadSpec`](mergesim_types::lanes::LaneRoadSpec):
//!
//! - **Ids**: the i-th drivable lane in the importer's order gets mergesim lane id i + 1;
//!   [`OpenDriveRoad::lanes`] maps each id back to its OpenDRIVE road id, lane-section index
//!   and `<lane id>` (`merge_sim opendrive dump FILE.xodr` prints the table).
//! - **Centreline**: the baked centreline, in travel direction (a lane driven against its
//!   road's reference line, `<lane id>` > 0 in right-hand traffic, is reversed), in the file's
//!   coordinates (x east, y north; heights dropped). The importer computes in `f32`: ≈ 0.5 mm
//!   resolution 6 km from the origin.
//! - **Widths**: the per-vertex widths, half to each side of the centreline.
//! - **Kind**: `entry`/`onRamp` → entry, `exit`/`offRamp` → exit, everything else → main.
//! - **Links**: successors and predecessors from the lane graph (road links and junctions);
//!   same-direction neighbours (the importer's lane-change edges) become the left or the right
//!   neighbour by the side their centreline lies on.
//! - **Tolerances**: as for CommonRoad maps, successors must start within 0.5 m of their
//!   predecessor's end.
//!
//! What is not taken: elevation and banking (the road is planar), lane layers other than the
//! permanent one, objects, signals and road marks.
//!
//! # Public API
//! - [`read_file`] and [`read_str`] give an [`OpenDriveRoad`]: the road of lanes and, per lane,
//!   its [`LaneOrigin`] in the file; errors are [`OpenDriveError`].
//! - Input limits: [`MAX_FILE_BYTES`], [`MAX_LANES`], [`MAX_COORDINATE_M`].

mod error;
mod road;

pub use error::OpenDriveError;
pub use road::{
    LaneOrigin, MAX_COORDINATE_M, MAX_FILE_BYTES, MAX_LANES, OpenDriveRoad, read_file, read_str,
};
