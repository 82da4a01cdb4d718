//! A driver without a planner: holds its spawn lane's centre and its target speed, blind to the
//! others (for deliberately unsafe tests).

use mergesim_types::lanes::{LaneId, LaneRoad};
use mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};

/// The point at arc length `s_m` and offset `d_m` of lane `lane`, following its first successor
/// past its end (the frame continues straight past the end of a lane without one).
fn point_along(lanes: &LaneRoad, lane: LaneId, mut s_m: f64, d_m: f64) -> Option<[f64; 2]> {
    let mut current = lanes.lane(lane)?;
    // Bounded: a road's successor chain is at most as long as its lane count.
    for _ in 0..lanes.lanes().len() {
        if s_m <= current.length_m() {
            break;
        }
        let Some(next) = current.successors().first().and_then(|id| lanes.lane(*id)) else {
            break;
        };
        s_m -= current.length_m();
        current = next;
    }
    Some(current.point(s_m, d_m))
}

/// A path along the centreline of `lane` (offset by `d_offset_m`, positive to the left), 50 m
/// ahead of the vehicle at `position_m` (projected on the lane) in 2.5 m steps of arc length,
/// with the speed `speed_at(distance ahead)` and times integrated from the mean speed of each
/// step, starting at `t_s`. Past the lane's end it follows the lane's first successor. On the
/// straight merge road: y = the lane's centre + offset, x from the vehicle's x on.
pub fn lane_path(
    lanes: &LaneRoad,
    lane: LaneId,
    d_offset_m: f64,
    position_m: [f64; 2],
    t_s: f64,
    speed_at: impl Fn(f64) -> f64,
) -> Vec<PathPoint> {
    const STEP_M: f64 = 2.5;
    const POINTS: usize = 21;
    let Some(s0_m) = lanes.lane(lane).map(|l| l.project(position_m).s_m) else {
        return Vec::new();
    };
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
        let Some([x_m, y_m]) = point_along(lanes, lane, s0_m + ahead_m, d_offset_m) else {
            break;
        };
        points.push(PathPoint {
            x_m,
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
    pub lane: LaneId,
    /// Offset from its centre (m, positive to the left).
    pub d_offset_m: f64,
}

impl Behaviour for LaneKeeping {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let v = obs.target_speed_mps;
        Ok(Decision::follow(lane_path(
            obs.lanes,
            self.lane,
            self.d_offset_m,
            [obs.ego.x_m, obs.ego.y_m],
            obs.time_s,
            |_| v,
        )))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
