//! The world read through its road of lanes (`crate::lane_membership`): lane changes as events
//! and the road's end.

use vehicles::Kinematics;

use mergesim_types::lanes::{LaneId, LaneRoad};

use super::World;
use crate::error::SimError;
use crate::event::SimEvent;
use crate::lane_membership::{lane_change, lane_of};

impl World {
    /// Updates every vehicle's lane (`crate::lane_membership`) and logs each lane change, in
    /// either direction, as an event.
    pub(super) fn log_lane_changes(
        &mut self,
        t_s: f64,
        kins: &[Kinematics],
    ) -> Result<(), SimError> {
        let mut changes = Vec::new();
        for (agent, k) in self.agents.iter_mut().zip(kins) {
            let hit = lane_of(&self.lanes, Some(agent.lane), [k.x_m, k.y_m]);
            if let Some(direction) = lane_change(&self.lanes, agent.lane, hit.lane) {
                changes.push(SimEvent::LaneChange {
                    t_s,
                    vehicle: agent.spec.name.clone(),
                    direction: direction.to_string(),
                    from_lane: agent.lane,
                    to_lane: hit.lane,
                    x_m: k.x_m,
                    y_m: k.y_m,
                });
            }
            agent.lane = hit.lane;
        }
        for event in changes {
            self.event(event)?;
        }
        Ok(())
    }
}

/// The lane whose open end (the road's end) the vehicle's front has passed, if any: the front
/// (the centre of gravity + `half_length_m` along the heading) lies beyond the end of the lane
/// the vehicle is in, and that lane ends without successors, open. On the straight merge road:
/// the front past `road.end_x_m`.
pub(super) fn past_road_end(
    lanes: &LaneRoad,
    current: LaneId,
    k: &Kinematics,
    half_length_m: f64,
) -> Option<LaneId> {
    let hit = lane_of(lanes, Some(current), [k.x_m, k.y_m]);
    let lane = lanes.lane(hit.lane)?;
    let open_end = lanes.lane_end(hit.lane).is_some_and(|e| !e.closed);
    if !open_end {
        return None;
    }
    let (s, c) = k.yaw_rad.sin_cos();
    let front_m = [k.x_m + half_length_m * c, k.y_m + half_length_m * s];
    (lane.project(front_m).s_m > lane.length_m()).then_some(hit.lane)
}
