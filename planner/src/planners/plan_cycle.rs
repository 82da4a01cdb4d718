//! The plan step of a [`PfPlanner`]: one planning cycle (Eqs. 1–10) and the speed term of its
//! kind (the risk of PF-SP, the interaction term of PF-ISO and PF-ISO-PRED).

use mergesim_types::{PathPoint, SharedLocalPath};

use super::{CycleFailure, PfPlanner};
use crate::Plan;
use crate::cubic_fit::{FitMethod, fit_path_cubic};
use crate::error::PlannerError;
use crate::following::{V2vLossFallback, following_cap_in_lane_frame_mps};
use crate::local_path::local_path_adaptive;
use crate::others::{
    RoleRules, arc_length_term, fixed_waypoint_term, gather_others, has_fresh_shared_path,
};
use crate::params::SlpReading;
use crate::planner_kind::PlannerKind;
use crate::polyline::Polyline;
use crate::potential_field::PotentialField;
use crate::request::PlanRequest;
use crate::speed_optimisation::{Aggregate, SpeedProblem, SpeedTerm, friction_speed_limits};
use crate::stop_and_go::{apply_caps, segment_time_s, stop_and_go_caps_mps};

fn non_finite(what: &str) -> PlannerError {
    PlannerError::NonFinite { what: what.into() }
}

/// Speed of `path` at absolute time `t_s`: that of the next point (a point carries the speed
/// reached there, i.e. of the step ending at it).
fn speed_at_time(path: &[PathPoint], t_s: f64) -> Option<f64> {
    let k = path.partition_point(|p| p.t_s <= t_s);
    path.get(k.min(path.len().saturating_sub(1)))
        .map(|p| p.speed_mps)
}

impl PfPlanner {
    /// The non-convex speed term of `kind` and its weight (None for PF-SP-EQ10, or with nobody
    /// around).
    /// Also returns the number of other vehicles it considers.
    fn speed_term(
        &self,
        kind: PlannerKind,
        req: &PlanRequest<'_>,
        line: &Polyline,
        waypoints: &[[f64; 2]],
    ) -> (Option<Box<dyn SpeedTerm>>, f64, usize) {
        let params = &self.params;
        let derived = &self.derived;
        let (use_shared_paths, weight) = match kind {
            PlannerKind::PfCs | PlannerKind::PfSpEq10 => return (None, 0.0, 0),
            PlannerKind::PfSp => (false, params.risk_weight),
            PlannerKind::PfIso => (true, params.interaction_weight),
            PlannerKind::PfIsoPred => (false, params.interaction_weight),
        };
        let others = gather_others(
            params.max_shared_path_age_s,
            &self.road,
            req,
            use_shared_paths,
            params.prediction,
        );
        let count = others.len();
        if others.is_empty() || weight <= 0.0 {
            return (None, weight, count);
        }
        let term: Box<dyn SpeedTerm> = if kind == PlannerKind::PfSp {
            // Risk along its own path: the path field, roles from the order now.
            let rules = RoleRules {
                rear_only: false,
                from_order_now: params.roles_from_order_now,
            };
            Box::new(arc_length_term(
                &derived.horizon,
                &derived.field.obstacles,
                rules,
                Aggregate::Linear,
                req,
                &others,
                line,
                &self.road,
            ))
        } else {
            let rules = RoleRules {
                rear_only: params.interaction_rear_only,
                from_order_now: params.roles_from_order_now,
            };
            match params.interaction_slp_reading {
                SlpReading::ArcLength => Box::new(arc_length_term(
                    &derived.horizon,
                    &derived.interaction_field,
                    rules,
                    Aggregate::LogFloored {
                        floor: params.interaction_floor,
                    },
                    req,
                    &others,
                    line,
                    &self.road,
                )),
                SlpReading::FixedWaypoints => Box::new(fixed_waypoint_term(
                    &derived.horizon,
                    &derived.interaction_field,
                    params.interaction_floor,
                    rules,
                    req,
                    &others,
                    waypoints,
                    &self.road,
                )),
            }
        };
        (Some(term), weight, count)
    }

    pub(super) fn plan_cycle(&mut self, req: &PlanRequest<'_>) -> Result<Plan, CycleFailure> {
        // The lane-end rule's walls: settled in a lane that goes on, now or at the last cycle.
        let (walls, settled_lane) = if self.params.lane_end_walls {
            self.road
                .lane_end_walls(&req.ego, 0.5 * req.ego_shape.width_m, self.settled_lane)
        } else {
            (Vec::new(), None)
        };
        self.settled_lane = settled_lane;
        let params = &self.params;
        let derived = &self.derived;
        let n = derived.horizon.waypoint_count;
        let fail = |error: PlannerError, waypoints: Option<Vec<[f64; 2]>>| CycleFailure {
            error,
            waypoints,
        };

        // Eqs. 1–7: waypoints by gradient steps.
        let mut field = PotentialField::new(
            &derived.field,
            &self.road,
            req.ego_id,
            &req.ego,
            &req.ego_shape,
            req.neighbours,
        );
        self.follow_route(&mut field, &req.ego);
        field.road.walls = walls;
        let step_m = params.step_length_m(req.ego.speed_mps);
        let time_per_step_s = if params.predict_obstacles_in_path {
            params.step_time_s
        } else {
            0.0
        };
        let waypoints = local_path_adaptive(
            &field,
            [req.ego.x_m, req.ego.y_m],
            step_m,
            n,
            params.max_substep_m,
            params.substep_max_turn_rad,
            time_per_step_s,
        );
        if waypoints.iter().flatten().any(|v| !v.is_finite()) {
            return Err(fail(non_finite("potential-field waypoints"), None));
        }

        // Eqs. 8–9: cubic in the vehicle frame.
        let (cubic, xis) = fit_path_cubic(
            &derived.cubic,
            [req.ego.x_m, req.ego.y_m],
            req.ego.yaw_rad,
            &waypoints,
        )
        .map_err(|e| fail(e, Some(waypoints.clone())))?;
        self.stats.cubic_qp = cubic.method == FitMethod::Qp;
        let points: Vec<[f64; 2]> = xis.iter().map(|xi| cubic.world_point(*xi)).collect();
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(fail(non_finite("fitted path"), Some(waypoints)));
        }
        let line = Polyline::with_start([req.ego.x_m, req.ego.y_m], points.iter().copied());
        let segment_lengths_m = line.segment_lengths_m();
        // Stop and go (`stop_and_go` module): caps down to 0 behind a slow or stopped vehicle;
        // None in moving traffic, which is then planned exactly as without it.
        let stop_caps_mps = stop_and_go_caps_mps(
            &derived.stop_and_go,
            &self.road,
            req,
            &points,
            self.stopping,
        );
        self.stopping = stop_caps_mps.is_some();
        self.stats.stop_and_go = self.stopping;

        // V2V lost (`following` module): a PF-ISO cycle without any fresh shared path around
        // plans its speeds as PF-SP, capped at the safe following speed.
        let heard_for_s = req.time_s - self.first_plan_s.unwrap_or(req.time_s);
        let degraded = self.kind == PlannerKind::PfIso
            && params.v2v_loss_fallback == V2vLossFallback::RiskAwareFollowing
            && heard_for_s > params.max_shared_path_age_s
            && req.neighbours.iter().any(|n| n.id != req.ego_id)
            && !has_fresh_shared_path(params.max_shared_path_age_s, req);
        self.stats.v2v_degraded = degraded;
        let speed_kind = if degraded {
            PlannerKind::PfSp
        } else {
            self.kind
        };

        // Speeds (Eq. 10, or PF-SP's risk-aware problem).
        let speeds_mps = match speed_kind {
            PlannerKind::PfCs => {
                let mut speeds_mps = vec![
                    req.target_speed_mps
                        .clamp(params.min_speed_mps, params.speed_limit_mps);
                    n
                ];
                if let Some(caps_mps) = &stop_caps_mps {
                    apply_caps(&mut speeds_mps, caps_mps);
                }
                speeds_mps
            }
            kind => {
                let mut max_speeds_mps = friction_speed_limits(
                    |xi| cubic.curvature_per_m(xi),
                    &xis,
                    req.mu,
                    params.speed_limit_mps,
                );
                let slows_only = match kind {
                    // Risk-aware speed planning lowers the speed for risk; it never races.
                    PlannerKind::PfSp => true,
                    _ => kind.is_interactive() && params.interaction_slows_only,
                };
                if slows_only {
                    // The non-convex term may only slow the vehicle: cap at V_target, or at a
                    // comfortable deceleration from the current speed if that is higher.
                    let decel_mps = derived.horizon.max_speed_change_mps;
                    for (i, v) in max_speeds_mps.iter_mut().enumerate() {
                        let from_now = req.ego.speed_mps - decel_mps * (i + 1) as f64;
                        *v = v.min(req.target_speed_mps.max(from_now));
                    }
                }
                if degraded
                    && let Some(cap_mps) = following_cap_in_lane_frame_mps(
                        &derived.following,
                        &self.road,
                        req.ego_id,
                        &req.ego,
                        &req.ego_shape,
                        req.neighbours,
                        &points,
                    )
                {
                    // Reached no faster than at a_max from the current speed (feasible).
                    let decel_mps = derived.horizon.max_speed_change_mps;
                    for (i, v) in max_speeds_mps.iter_mut().enumerate() {
                        let from_now = req.ego.speed_mps - decel_mps * (i + 1) as f64;
                        *v = v.min(cap_mps.max(from_now).max(params.min_speed_mps));
                    }
                }
                if let Some(caps_mps) = &stop_caps_mps {
                    apply_caps(&mut max_speeds_mps, caps_mps);
                }
                let (term, weight, count) = self.speed_term(kind, req, &line, &waypoints);
                self.stats.interacting_vehicles = count;
                // Warm start: the last good plan's speeds at the same absolute times.
                let guess: Option<Vec<f64>> = self.last_good.as_ref().and_then(|last| {
                    (1..=n)
                        .map(|i| {
                            speed_at_time(
                                &last.path,
                                req.time_s + (i as f64 - 0.5) * derived.horizon.step_time_s,
                            )
                        })
                        .collect()
                });
                let problem = SpeedProblem {
                    current_speed_mps: req.ego.speed_mps,
                    target_speed_mps: req.target_speed_mps,
                    segment_lengths_m: &segment_lengths_m,
                    max_speeds_mps: &max_speeds_mps,
                    initial_guess_mps: guess.as_deref(),
                    interaction: term.as_deref(),
                    interaction_weight: weight,
                };
                let solution = self
                    .optimiser
                    .solve(&derived.speed, &problem)
                    .map_err(|e| fail(e, Some(waypoints.clone())))?;
                self.stats.speed_solves = solution.solves;
                self.stats.speed_stopped_at_iteration_cap = solution.stopped_at_iteration_cap;
                let mut speeds_mps = solution.speeds_mps;
                if let Some(caps_mps) = &stop_caps_mps {
                    // Below v_min, the cap itself (`stop_and_go` module doc, item 3).
                    apply_caps(&mut speeds_mps, caps_mps);
                }
                speeds_mps
            }
        };

        // The path to track and the SLP: t_i = t_0 + Σ Δs_j / v_j. The profile starts at the
        // current speed v_0 at t_0 and reaches v_i at point i (the speed of step i is its value
        // at the step's end, as the bound |v_i − v_{i−1}| ≤ a_max Δt assumes): the first point
        // carries v_0, not v_1, so the plan is no step a car cannot follow.
        let mut path = Vec::with_capacity(n + 1);
        let mut t_s = req.time_s;
        path.push(PathPoint {
            x_m: req.ego.x_m,
            y_m: req.ego.y_m,
            speed_mps: req.ego.speed_mps.max(0.0),
            t_s,
        });
        for (k, p) in points.iter().enumerate() {
            t_s += if stop_caps_mps.is_some() {
                segment_time_s(segment_lengths_m[k], speeds_mps[k])
            } else {
                segment_lengths_m[k] / speeds_mps[k]
            };
            path.push(PathPoint {
                x_m: p[0],
                y_m: p[1],
                speed_mps: speeds_mps[k],
                t_s,
            });
        }
        if path.iter().any(|p| {
            !(p.x_m.is_finite()
                && p.y_m.is_finite()
                && p.speed_mps.is_finite()
                && p.t_s.is_finite())
        }) {
            return Err(fail(non_finite("planned path"), Some(waypoints)));
        }
        let shared = SharedLocalPath::from_path(
            req.ego_id,
            req.time_s,
            req.ego_shape,
            req.ego.speed_mps,
            &path,
        );
        Ok(Plan {
            waypoints,
            path,
            cubic: cubic.coefficients,
            cubic_x_scale_m: cubic.x_scale_m,
            shared,
            fallback: None,
        })
    }
}
