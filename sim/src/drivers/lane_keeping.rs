//! A driver without a planner: holds its spawn lane's centre and its target speed, blind to the
//! others (for deliberately unsafe tests).

use mergesim_types::{
    Behaviour, BehaviourError, Decision, Lane, MergeRoad, Observation, PathPoint,
};

/// A straight path along the centre of `lane` (plus `y_offset_m`), 50 m ahead of `x_m` in 2.5 m
/// steps, with the speed `speed_at(distance ahead)` and times integrated from the mean speed of
/// each step, starting at `t_s`.
pub fn lane_path(
    road: &MergeRoad,
    lane: Lane,
    y_offset_m: f64,
    x_m: f64,
    t_s: f64,
    speed_at: impl Fn(f64) -> f64,
) -> Vec<PathPoint> {
    const STEP_M: f64 = 2.5;
    const POINTS: usize = 21;
    let y_m = road.lane_center_y_m(lane) + y_offset_m;
    let mut points = Vec::with_capacity(POINTS);
    let mut t = t_s;
    let mut previous_speed = speed_at(0.0);
    for i in 0..POINTS {
        let ahead_m = STEP_M * i as f64;
        let speed_mps = speed_at(ahead_m);
        if i > 0 {
            t += STEP_M / (0.5 * (previous_speed + speed_mps)).max(0.1);
        }
        previous_speed = speed_mps;
        points.push(PathPoint {
            x_m: x_m + ahead_m,
            y_m,
            speed_mps,
            t_s: t,
        });
    }
    points
}

/// Lane keeping at the target speed (module doc).
#[derive(Clone, Debug)]
pub struct LaneKeeping {
    /// Lane to hold.
    pub lane: Lane,
    /// Offset from its centre (m).
    pub y_offset_m: f64,
}

impl Behaviour for LaneKeeping {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let v = obs.target_speed_mps;
        Ok(Decision::follow(lane_path(
            obs.road,
            self.lane,
            self.y_offset_m,
            obs.ego.x_m,
            obs.time_s,
            |_| v,
        )))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
