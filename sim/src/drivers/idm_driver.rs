//! A human driver: Intelligent Driver Model car following (`crate::idm`) along its spawn lane;
//! never changes lanes, never connected. Gaps are measured in the held lane's frame (s along it,
//! d across it), so the model follows curved lanes.

use mergesim_types::lanes::LaneId;
use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};

use crate::drivers::lane_path;
use crate::idm::{IdmParams, RoadUser, find_leader, idm_acceleration, speed_after_distance};

/// IDM car following with lane keeping (module doc).
#[derive(Clone, Debug)]
pub struct IdmDriver {
    /// The model's parameters.
    pub params: IdmParams,
    /// Lane to hold.
    pub lane: LaneId,
    /// Offset from its centre (m, positive to the left).
    pub d_offset_m: f64,
}

impl Behaviour for IdmDriver {
    /// The acceleration of the IDM behind the nearest vehicle ahead in its corridor, turned into
    /// the speed profile of a lane-keeping path.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        // Everybody in the held lane's frame: s along it, d across it.
        let Some(lane) = obs.lanes.lane(self.lane) else {
            return Err(format!("lane {} is not on the road", self.lane).into());
        };
        let user = |x_m: f64, y_m: f64, speed_mps: f64, length_m: f64| {
            let fp = lane.project([x_m, y_m]);
            RoadUser {
                x_m: fp.s_m,
                y_m: fp.d_m,
                speed_mps,
                length_m,
            }
        };
        let users: Vec<RoadUser> = std::iter::once(user(
            obs.ego.x_m,
            obs.ego.y_m,
            obs.ego.speed_mps,
            obs.ego_shape.length_m,
        ))
        .chain(obs.neighbours.iter().map(|n| {
            user(
                n.state.x_m,
                n.state.y_m,
                n.state.speed_mps,
                n.shape.length_m,
            )
        }))
        .collect();
        let leader = find_leader(&self.params, &users, 0);
        let v = obs.ego.speed_mps;
        let accel_mps2 = idm_acceleration(&self.params, v, obs.target_speed_mps, leader.as_ref());
        Ok(Decision::follow(lane_path(
            obs.lanes,
            self.lane,
            self.d_offset_m,
            [obs.ego.x_m, obs.ego.y_m],
            obs.time_s,
            |d| speed_after_distance(v, accel_mps2, d),
        )))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
