//! A human driver: Intelligent Driver Model car following (`crate::idm`) along its spawn lane;
//! never changes lanes, never connected.

use mergesim_types::{Behaviour, BehaviourError, Decision, Lane, Observation};

use crate::drivers::lane_path;
use crate::idm::{IdmParams, RoadUser, find_leader, idm_acceleration, speed_after_distance};

/// IDM car following with lane keeping (module doc).
#[derive(Clone, Debug)]
pub struct IdmDriver {
    /// The model's parameters.
    pub params: IdmParams,
    /// Lane to hold.
    pub lane: Lane,
    /// Offset from its centre (m).
    pub y_offset_m: f64,
}

impl Behaviour for IdmDriver {
    /// The acceleration of the IDM behind the nearest vehicle ahead in its corridor, turned into
    /// the speed profile of a lane-keeping path.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let users: Vec<RoadUser> = std::iter::once(RoadUser {
            x_m: obs.ego.x_m,
            y_m: obs.ego.y_m,
            speed_mps: obs.ego.speed_mps,
            length_m: obs.ego_shape.length_m,
        })
        .chain(obs.neighbours.iter().map(|n| RoadUser {
            x_m: n.state.x_m,
            y_m: n.state.y_m,
            speed_mps: n.state.speed_mps,
            length_m: n.shape.length_m,
        }))
        .collect();
        let leader = find_leader(&self.params, &users, 0);
        let v = obs.ego.speed_mps;
        let accel_mps2 = idm_acceleration(&self.params, v, obs.target_speed_mps, leader.as_ref());
        Ok(Decision::follow(lane_path(
            obs.road,
            self.lane,
            self.y_offset_m,
            obs.ego.x_m,
            obs.time_s,
            |d| speed_after_distance(v, accel_mps2, d),
        )))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
