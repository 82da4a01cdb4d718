//! `mergesim.Road`: the road as lanes, as a Python planner sees it (`observation["road"]`): lane
//! ids, where a point lies in a lane's (s, d) frame, and points of a lane's centreline. A thin
//! view of the simulator's `LaneRoad` (the road every built-in planner reads), shared, not copied.

use std::sync::Arc;

use mergesim_types::lanes::{Lane, LaneId, LaneRoad};
use pyo3::prelude::*;

use crate::errors::BindingError;

/// Most points one `centreline` call returns.
const MAX_SAMPLES: usize = 100_000;

/// The road of a run, as lanes (module doc). s is the arc length along a lane's centreline (m),
/// d the lateral offset from it (m, positive to the left of the direction of travel); a lane's
/// frame continues straight before its start and past its end.
#[pyclass(frozen, module = "mergesim._native", name = "Road")]
pub(crate) struct Road {
    lanes: Arc<LaneRoad>,
}

impl Road {
    /// A view of `lanes`.
    pub(crate) fn new(lanes: Arc<LaneRoad>) -> Self {
        Self { lanes }
    }

    fn lane(&self, lane: u32) -> PyResult<&Lane> {
        self.lanes.lane(LaneId(lane)).ok_or_else(|| {
            let ids: Vec<String> = self
                .lanes
                .lanes()
                .iter()
                .map(|l| l.id().0.to_string())
                .collect();
            BindingError::Input(format!(
                "lane {lane}: not a lane of this road (lanes: {})",
                ids.join(", ")
            ))
            .into()
        })
    }
}

#[pymethods]
impl Road {
    /// The lane ids, in the road's order.
    fn lane_ids(&self) -> Vec<u32> {
        self.lanes.lanes().iter().map(|l| l.id().0).collect()
    }

    /// The lane nearest to the point (x_m, y_m): (lane id, s_m, d_m) of the point in its frame.
    fn nearest_lane(&self, x_m: f64, y_m: f64) -> (u32, f64, f64) {
        let hit = self.lanes.nearest_lane([x_m, y_m]);
        (hit.lane.0, hit.frame.s_m, hit.frame.d_m)
    }

    /// Where the point (x_m, y_m) lies in lane `lane`'s frame: (s_m, d_m).
    fn project(&self, lane: u32, x_m: f64, y_m: f64) -> PyResult<(f64, f64)> {
        let frame = self.lane(lane)?.project([x_m, y_m]);
        Ok((frame.s_m, frame.d_m))
    }

    /// The point (x_m, y_m) at (s_m, d_m) of lane `lane`'s frame.
    #[pyo3(signature = (lane, s_m, d_m = 0.0))]
    fn point(&self, lane: u32, s_m: f64, d_m: f64) -> PyResult<(f64, f64)> {
        let [x_m, y_m] = self.lane(lane)?.point(s_m, d_m);
        Ok((x_m, y_m))
    }

    /// Points (x_m, y_m) of lane `lane` at offset `d_m` from its centreline, every `step_m` from
    /// `s_from_m` to `s_to_m` (included when it falls on a step).
    #[pyo3(signature = (lane, s_from_m, s_to_m, step_m, d_m = 0.0))]
    fn centreline(
        &self,
        lane: u32,
        s_from_m: f64,
        s_to_m: f64,
        step_m: f64,
        d_m: f64,
    ) -> PyResult<Vec<(f64, f64)>> {
        let lane = self.lane(lane)?;
        let finite = s_from_m.is_finite() && s_to_m.is_finite() && step_m.is_finite();
        if !finite || step_m <= 0.0 {
            return Err(BindingError::Input(format!(
                "centreline: need finite s_from_m, s_to_m and step_m > 0, got {s_from_m}, \
                 {s_to_m}, {step_m}"
            ))
            .into());
        }
        let count = ((s_to_m - s_from_m) / step_m).floor().max(-1.0) + 1.0;
        if count > MAX_SAMPLES as f64 {
            return Err(BindingError::Input(format!(
                "centreline: {count} points asked for, at most {MAX_SAMPLES}"
            ))
            .into());
        }
        Ok((0..count as usize)
            .map(|i| {
                let [x_m, y_m] = lane.point(s_from_m + step_m * i as f64, d_m);
                (x_m, y_m)
            })
            .collect())
    }

    /// The heading of lane `lane`'s centreline at `s_m` (rad, counter-clockwise from +x).
    fn heading_rad(&self, lane: u32, s_m: f64) -> PyResult<f64> {
        Ok(self.lane(lane)?.heading_rad(s_m))
    }

    /// The width of lane `lane` at `s_m` (m).
    fn width_m(&self, lane: u32, s_m: f64) -> PyResult<f64> {
        Ok(self.lane(lane)?.width_m(s_m))
    }

    /// The length of lane `lane`'s centreline (m).
    fn length_m(&self, lane: u32) -> PyResult<f64> {
        Ok(self.lane(lane)?.length_m())
    }

    /// The same-direction neighbours of lane `lane`: (left id or None, right id or None).
    fn neighbours(&self, lane: u32) -> PyResult<(Option<u32>, Option<u32>)> {
        let lane = self.lane(lane)?;
        Ok((
            lane.left_neighbour().map(|l| l.0),
            lane.right_neighbour().map(|l| l.0),
        ))
    }

    /// The lanes lane `lane` flows into.
    fn successors(&self, lane: u32) -> PyResult<Vec<u32>> {
        Ok(self.lane(lane)?.successors().iter().map(|l| l.0).collect())
    }

    /// How far ahead of `s_m` (m) lane `lane` must be left because every way on from it ends
    /// closed (a lane drop, the merge lane's end); None if it goes on to the road's end.
    fn distance_to_closed_end_m(&self, lane: u32, s_m: f64) -> PyResult<Option<f64>> {
        self.lane(lane)?;
        Ok(self.lanes.distance_to_closed_end_m(LaneId(lane), s_m))
    }

    fn __repr__(&self) -> String {
        format!("Road(lanes={:?})", self.lane_ids())
    }
}
