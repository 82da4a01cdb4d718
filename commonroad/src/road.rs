//! The lanelet network as a road of lanes ([`LaneRoadSpec`]), in the file's coordinates.
//!
//! - **Centreline**: the midpoints of the left and right bounds' vertices (CommonRoad pairs
//!   them: vertex i of the left bound faces vertex i of the right one).
//! - **Widths**: per vertex, the distances from the centreline vertex to the two bound
//!   vertices, `left_width_m[i] = right_width_m[i] = |l_i − r_i| / 2`. The lane road measures
//!   widths along its frame's normal, so where a pair (l_i, r_i) is not square to the
//!   centreline the rebuilt bound moves by up to half the width × (1 − cos of the skew); the
//!   test `rebuilt_bounds_match_the_file` measures it on the test files: the file's bound
//!   vertices lie at most 0.011 m (US-101) and 0.069 m (A9) from the rebuilt bounds
//!   (`cargo test --release -p mergesim-commonroad --test test_files -- --nocapture`,
//!   2026-12-02). Vertices closer than 5 cm are merged by the lane road's cleaning.
//! - **Neighbours**: `adjacentLeft` / `adjacentRight` with `drivingDir="same"` become the
//!   lane's `left` / `right`. An opposite-direction neighbour is no neighbour link (a vehicle
//!   does not change lanes into oncoming traffic); the opposite lanelet itself is kept as a lane
//!   driven along its own bounds' direction, so the drivable area (the union of the lanes)
//!   includes the other carriageway and the boundary between the two is not an outer edge.
//! - **Links**: `successor` / `predecessor` as they are.
//! - **Kind**: `laneletType` `accessRamp` → entry, `exitRamp` → exit, `shoulder` → shoulder,
//!   anything else (and 2018b, which has no type) → main.
//! - **Tolerances**: [`commonroad_tolerances`]: successors must start within 0.5 m of their
//!   predecessor's end (recorded maps are digitised by hand; the default 0.1 m is for built
//!   roads).

use mergesim_types::lanes::{LaneId, LaneKind, LaneRoadSpec, LaneSpec, LaneTolerances};

use crate::model::{Adjacent, DrivingDir, Scenario};

/// The tolerances used for CommonRoad networks (see the module docs).
pub fn commonroad_tolerances() -> LaneTolerances {
    LaneTolerances {
        link_m: 0.5,
        ..LaneTolerances::default()
    }
}

fn lane_id(id: i64) -> LaneId {
    // The reader refuses lanelet ids outside the u32 range.
    LaneId(u32::try_from(id).unwrap_or(u32::MAX))
}

fn same_dir(a: Option<Adjacent>) -> Option<LaneId> {
    a.filter(|a| a.driving_dir == DrivingDir::Same)
        .map(|a| lane_id(a.id))
}

/// The lanelet network of `scenario` as a road of lanes (see the module docs). Build it with
/// [`LaneRoad::new`](mergesim_types::lanes::LaneRoad::new), which refuses an inconsistent
/// network with a [`LaneError`](mergesim_types::lanes::LaneError) naming the lanelet.
pub fn lane_road_spec(scenario: &Scenario) -> LaneRoadSpec {
    let lanes = scenario
        .lanelets
        .iter()
        .map(|l| {
            let mut centreline_m = Vec::with_capacity(l.left_bound_m.len());
            let mut half_width_m = Vec::with_capacity(l.left_bound_m.len());
            for (a, b) in l.left_bound_m.iter().zip(&l.right_bound_m) {
                centreline_m.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
                half_width_m.push(0.5 * (a[0] - b[0]).hypot(a[1] - b[1]));
            }
            let kind = if l.lanelet_types.iter().any(|t| t == "accessRamp") {
                LaneKind::Entry
            } else if l.lanelet_types.iter().any(|t| t == "exitRamp") {
                LaneKind::Exit
            } else if l.lanelet_types.iter().any(|t| t == "shoulder") {
                LaneKind::Shoulder
            } else {
                LaneKind::Main
            };
            LaneSpec {
                id: lane_id(l.id),
                kind,
                centreline_m,
                width_m: Vec::new(),
                left_width_m: half_width_m.clone(),
                right_width_m: half_width_m,
                left: same_dir(l.adjacent_left),
                right: same_dir(l.adjacent_right),
                successors: l.successors.iter().map(|&s| lane_id(s)).collect(),
                predecessors: l.predecessors.iter().map(|&s| lane_id(s)).collect(),
            }
        })
        .collect();
    LaneRoadSpec {
        lanes,
        tolerances: commonroad_tolerances(),
    }
}
