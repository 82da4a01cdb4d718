//! The adaptive cruise control of examples/custom_planner.rs and examples/own_planner_cli.rs:
//! it keeps the lane it is in (its centreline, through `Observation::lanes`) and its target
//! speed, but never closes in on a vehicle ahead in its lane (or within a metre of entering it)
//! faster than a constant time gap allows, and broadcasts its path.

use std::sync::Arc;

use mergesim::mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};
use mergesim::sim::registry::{BehaviourFactory, FactoryInput};

/// Constant-time-gap cruise control along the through lane.
pub struct TimeGapCruise {
    /// Desired time gap to the vehicle ahead (s).
    pub time_gap_s: f64,
    /// Standstill gap, bumper to bumper (m).
    pub min_gap_m: f64,
}

impl Behaviour for TimeGapCruise {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        // The lane the car is in, and where along it (s, d) the car and the others are.
        let here = obs.lanes.nearest_lane([obs.ego.x_m, obs.ego.y_m]);
        let Some(lane) = obs.lanes.lane(here.lane) else {
            return Err("the car is on no lane".into());
        };
        let half_width_m = 0.5 * lane.width_m(here.frame.s_m);
        // The nearest vehicle ahead that is in this lane or within a metre of entering it.
        let ahead = obs
            .neighbours
            .iter()
            .map(|n| (n, lane.project([n.state.x_m, n.state.y_m])))
            .filter(|(_, f)| f.s_m > here.frame.s_m && f.d_m.abs() < half_width_m + 1.0)
            .min_by(|a, b| a.1.s_m.total_cmp(&b.1.s_m));
        let speed_mps = match ahead {
            Some((n, f)) => {
                let gap_m =
                    f.s_m - here.frame.s_m - 0.5 * (n.shape.length_m + obs.ego_shape.length_m);
                let keeps_gap_mps = (gap_m - self.min_gap_m).max(0.0) / self.time_gap_s;
                obs.target_speed_mps
                    .min(keeps_gap_mps.max(n.state.speed_mps.min(obs.target_speed_mps)))
            }
            None => obs.target_speed_mps,
        }
        .max(0.5);
        // Points along the lane's centreline (its frame continues straight past its end).
        let path: Vec<PathPoint> = (0..=20)
            .map(|i| {
                let ahead_m = 4.0 * i as f64;
                let [x_m, y_m] = if i == 0 {
                    [obs.ego.x_m, obs.ego.y_m]
                } else {
                    lane.point(here.frame.s_m + ahead_m, 0.0)
                };
                PathPoint {
                    x_m,
                    y_m,
                    speed_mps,
                    t_s: obs.time_s + ahead_m / speed_mps,
                }
            })
            .collect();
        Ok(Decision::follow_and_share(path, obs))
    }
}

/// The factory to register: every vehicle gets its own cruise control, 1.5 s and 2 m.
pub fn time_gap_cruise_factory() -> BehaviourFactory {
    Arc::new(|_: &FactoryInput<'_>| {
        Ok(Box::new(TimeGapCruise {
            time_gap_s: 1.5,
            min_gap_m: 2.0,
        }) as Box<dyn Behaviour>)
    })
}
