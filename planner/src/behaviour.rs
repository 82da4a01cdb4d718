//! The potential-field planners as a vehicle [`Behaviour`] (the simulator's extension point).

use mergesim_types::{
    Behaviour, BehaviourError, Decision, DegradedMode, GridSpec, Observation, OptimiserReport,
};

use crate::planners::PfPlanner;
use crate::request::PlanRequest;

/// The planner's request of an observation.
fn request<'a>(obs: &Observation<'a>) -> PlanRequest<'a> {
    PlanRequest {
        time_s: obs.time_s,
        ego_id: obs.ego_id,
        ego: obs.ego,
        ego_shape: obs.ego_shape,
        target_speed_mps: obs.target_speed_mps,
        mu: obs.mu,
        neighbours: obs.neighbours,
        shared_paths: obs.shared_paths,
    }
}

impl Behaviour for PfPlanner {
    /// One planning cycle ([`PfPlanner::plan`]): the fitted path with its speeds and times, and
    /// the same timed points as the shared local path. A fallback plan carries its reason.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let plan = PfPlanner::plan(self, &request(obs))?;
        Ok(Decision {
            fallback: plan.fallback.clone(),
            path: plan.path,
            broadcast: Some(plan.shared),
            degraded_mode: self
                .last_stats()
                .v2v_degraded
                .then_some(DegradedMode::V2vLost),
        })
    }

    /// The speed optimisation of the last cycle (PF-CS has none: no solves) and whether its
    /// cubic fit (Eqs. 8–9) met a bound.
    fn optimiser_report(&self) -> Option<OptimiserReport> {
        let stats = self.last_stats();
        Some(OptimiserReport {
            solves: u32::try_from(stats.speed_solves).unwrap_or(u32::MAX),
            stopped_at_iteration_cap: stats.speed_stopped_at_iteration_cap,
            path_fit_bound_active: stats.cubic_qp,
        })
    }

    /// U_uni with the attraction (the field Eq. 7 steps in) on the grid.
    fn potential_field(&self, obs: &Observation<'_>, spec: &GridSpec) -> Option<Vec<f64>> {
        self.field_grid(&request(obs), spec, true).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlannerKind;
    use crate::params::PlannerParams;
    use mergesim_types::{MergeRoad, VehicleShape, VehicleState};

    #[test]
    fn the_behaviour_is_the_plan_with_its_shared_path() {
        let road = MergeRoad::default();
        let obs = Observation {
            time_s: 1.0,
            ego_id: 0,
            ego: VehicleState {
                x_m: 0.0,
                y_m: 1.75,
                yaw_rad: 0.0,
                speed_mps: 20.0,
            },
            ego_shape: VehicleShape::default(),
            target_speed_mps: 20.0,
            mu: 0.8,
            lanes: &road.lane_road().unwrap(),
            neighbours: &[],
            shared_paths: &[],
        };
        let new = || {
            PfPlanner::new(
                PlannerKind::PfIso,
                PlannerParams::default(),
                road.lane_road().unwrap(),
            )
        };
        let mut behaviour = new().unwrap();
        let decision = Behaviour::plan(&mut behaviour, &obs).unwrap();
        let plan = new().unwrap().plan(&request(&obs)).unwrap();
        assert_eq!(decision.path, plan.path);
        assert_eq!(decision.broadcast, Some(plan.shared));
        assert_eq!(decision.fallback, None);
        let spec = GridSpec {
            x_min_m: 0.0,
            y_min_m: 0.0,
            cell_m: 1.0,
            columns: 3,
            rows: 2,
        };
        assert_eq!(
            behaviour.potential_field(&obs, &spec).map(|v| v.len()),
            Some(6)
        );
    }
}
