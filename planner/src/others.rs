//! What a planning vehicle knows about the others for its speed choice (Eq. 10 and PF-SP), and
//! the non-convex speed terms built from it.
//!
//! Each other vehicle comes with a `Trajectory`: its received shared local path (PF-ISO, if
//! fresh) or a prediction from its perceived state (`PlannerParams::prediction`; PF-ISO-PRED and
//! PF-SP always, PF-ISO for a vehicle without a fresh SLP), and whether it is ahead of the
//! planning vehicle *now* (larger s along the ego's lane).
//!
//! Roles (who keeps the gap) shape each other vehicle's field:
//! - a received SLP is the sender's declared intent: with `interaction_rear_only` the roles are
//!   read per time slot from the shared positions (behind it I follow: its full rear D_min;
//!   ahead of it it follows: its front shrunk to the contact distance);
//! - a prediction is not an intent: with `roles_from_order_now` the roles are fixed
//!   from the order now for the whole horizon — a vehicle ahead keeps its full by-side D_min on
//!   both sides (I follow it, and must leave it its gap if I pass and cut in), a vehicle behind
//!   only its contact distance (it follows me and keeps the gap, whatever the prediction says).
//!   Per-slot roles on constant-velocity predictions let two vehicles each see the other
//!   overtaking and race to stay ahead (docs/reproduction.md, "Where the two equilibria meet").

use std::collections::BTreeMap;

use crate::derived_params::PlanHorizon;
use crate::lane_road_field::LaneRoadGeometry;
use crate::obstacle_field::HeadingForm;
use crate::obstacle_field::{ObstacleField, ObstacleFieldParams, Role, SelfView};
use crate::polyline::Polyline;
use crate::prediction::{PredictionModel, Trajectory};
use crate::request::PlanRequest;
use crate::speed_optimisation::fixed_waypoint_term::SlotOther;
use crate::speed_optimisation::{Aggregate, FixedWaypointTerm, InteractionTerm};
use mergesim_types::{SharedLocalPath, VehicleId, VehicleShape};

/// Another vehicle as the speed terms see it.
#[derive(Clone, Debug)]
pub struct Other {
    /// Its id.
    pub id: VehicleId,
    /// Its motion: received SLP or prediction.
    pub trajectory: Trajectory,
    /// Its speed now (m/s).
    pub speed_mps: f64,
    /// Its shape.
    pub shape: VehicleShape,
    /// Whether it is ahead of the planning vehicle now (larger s along the ego's lane).
    pub ahead_now: bool,
}

/// The newest fresh SLP of each sender other than the ego: one at most `max_age_s` old
/// (`max_shared_path_age_s`).
fn fresh_shared_paths<'a>(
    max_age_s: f64,
    req: &PlanRequest<'a>,
) -> BTreeMap<VehicleId, &'a SharedLocalPath> {
    let mut newest: BTreeMap<VehicleId, &SharedLocalPath> = BTreeMap::new();
    for m in req.shared_paths {
        let age_s = req.time_s - m.stamp_s;
        if m.vehicle_id == req.ego_id || age_s > max_age_s {
            continue;
        }
        match newest.get(&m.vehicle_id) {
            Some(old) if old.stamp_s >= m.stamp_s => {}
            _ => {
                newest.insert(m.vehicle_id, m);
            }
        }
    }
    newest
}

/// Whether any vehicle other than the ego has a fresh SLP in `req`, at most `max_age_s` old
/// (`max_shared_path_age_s`; else PF-ISO has lost V2V, or nobody around is connected).
pub fn has_fresh_shared_path(max_age_s: f64, req: &PlanRequest<'_>) -> bool {
    !fresh_shared_paths(max_age_s, req).is_empty()
}

/// The others, by id: received SLPs at most `max_age_s` old (`max_shared_path_age_s`) if
/// `use_shared_paths` (PF-ISO), then a prediction with `model` for every perceived neighbour
/// without one. "Ahead" is measured along the frame of the ego's lane (larger s).
pub fn gather_others(
    max_age_s: f64,
    road: &LaneRoadGeometry,
    req: &PlanRequest<'_>,
    use_shared_paths: bool,
    model: PredictionModel,
) -> Vec<Other> {
    let mut others: BTreeMap<VehicleId, Other> = BTreeMap::new();
    let ego_p = [req.ego.x_m, req.ego.y_m];
    let ego_lane = road.lane_index_at(ego_p);
    let ego_s_m = road.s_m(ego_lane, ego_p);
    let ahead = |p: [f64; 2]| road.s_m(ego_lane, p) > ego_s_m;
    if use_shared_paths {
        for (id, m) in fresh_shared_paths(max_age_s, req) {
            let perceived = req.neighbours.iter().find(|n| n.id == id);
            let yaw = perceived.map_or(0.0, |n| n.state.yaw_rad);
            let p_now_m = perceived
                .map(|n| [n.state.x_m, n.state.y_m])
                .or_else(|| m.waypoints.first().map(|w| [w.x_m, w.y_m]))
                .unwrap_or(ego_p);
            if let Some(trajectory) = Trajectory::from_shared(m, yaw) {
                others.insert(
                    id,
                    Other {
                        id,
                        trajectory,
                        speed_mps: m.speed_mps,
                        shape: m.shape,
                        ahead_now: ahead(p_now_m),
                    },
                );
            }
        }
    }
    for n in req.neighbours {
        if n.id == req.ego_id || others.contains_key(&n.id) {
            continue;
        }
        others.insert(
            n.id,
            Other {
                id: n.id,
                trajectory: model.trajectory(n.state, req.time_s, road),
                speed_mps: n.state.speed_mps,
                shape: n.shape,
                ahead_now: ahead([n.state.x_m, n.state.y_m]),
            },
        );
    }
    others.into_values().collect()
}

/// How the roles shape one other vehicle's field (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RoleRules {
    /// Per-slot roles for received SLPs: the front shrunk to the contact distance.
    pub rear_only: bool,
    /// Fixed roles from the order now for predicted vehicles.
    pub from_order_now: bool,
}

/// The role `rules` give `other` (module doc).
fn role_of(rules: RoleRules, other: &Other) -> Role {
    if other.trajectory.is_predicted() && rules.from_order_now {
        if other.ahead_now {
            Role::Full
        } else {
            Role::ContactOnly
        }
    } else if rules.rear_only {
        Role::RearOnly
    } else {
        Role::Full
    }
}

/// The field of `other` centred at the origin with heading 0 (moved per slot later), seen by
/// the ego of `req`, with its role applied; `x_scale` is `field_params.x_scale()`.
fn base_field(
    field_params: &ObstacleFieldParams,
    x_scale: f64,
    rules: RoleRules,
    req: &PlanRequest<'_>,
    other: &Other,
) -> ObstacleField {
    let me = SelfView {
        speed_mps: req.ego.speed_mps,
        shape: req.ego_shape,
    };
    let field = ObstacleField::new(
        field_params,
        me,
        0.0,
        0.0,
        0.0,
        other.speed_mps,
        &other.shape,
    );
    let contact_m = 0.5 * (req.ego_shape.length_m + other.shape.length_m);
    field.with_role(role_of(rules, other), contact_m, x_scale)
}

/// `base` moved to a pose; for the correlation form of Eq. 4 its heading is taken relative to
/// the lane at the pose (the rotation form needs no lane: its ellipse is the vehicle's frame).
fn moved_in_lane(
    base: &ObstacleField,
    road: &LaneRoadGeometry,
    xy_m: [f64; 2],
    heading: [f64; 2],
) -> ObstacleField {
    let moved = base.moved_to(xy_m[0], xy_m[1], heading[0], heading[1]);
    match moved.heading_form {
        HeadingForm::Rotation => moved,
        HeadingForm::PaperCorrelation => moved.in_lane_frame(road.lane_heading_at_rad(xy_m)),
    }
}

/// Absolute time of slot i (1-based): t_0 + i·Δt_plan.
fn slot_time_s(horizon: &PlanHorizon, req: &PlanRequest<'_>, i: usize) -> f64 {
    req.time_s + i as f64 * horizon.step_time_s
}

/// The arc-length term (module doc of `speed_optimisation::interaction_term`): the others'
/// fields at their poses at each of the `horizon`'s slot times, against the ego's position
/// along `line`.
#[allow(clippy::too_many_arguments)] // the term's inputs, each used once
pub(crate) fn arc_length_term(
    horizon: &PlanHorizon,
    field_params: &ObstacleFieldParams,
    rules: RoleRules,
    aggregate: Aggregate,
    req: &PlanRequest<'_>,
    others: &[Other],
    line: &Polyline,
    road: &LaneRoadGeometry,
) -> InteractionTerm {
    let n = horizon.waypoint_count;
    let x_scale = field_params.x_scale();
    let bases: Vec<(ObstacleField, &Trajectory)> = others
        .iter()
        .map(|o| {
            (
                base_field(field_params, x_scale, rules, req, o),
                &o.trajectory,
            )
        })
        .collect();
    let fields = (1..=n)
        .map(|i| {
            let t_s = slot_time_s(horizon, req, i);
            bases
                .iter()
                .map(|(base, trajectory)| {
                    let pose = trajectory.pose_at(t_s);
                    moved_in_lane(base, road, pose.xy_m, pose.heading)
                })
                .collect()
        })
        .collect();
    let (sin_yaw, cos_yaw) = req.ego.yaw_rad.sin_cos();
    InteractionTerm::new(
        line.clone(),
        [cos_yaw, sin_yaw],
        horizon.step_time_s,
        aggregate,
        fields,
    )
}

/// The paper's reading of U_SLP (module doc of `speed_optimisation::fixed_waypoint_term`): the
/// ego's Eq. 7 waypoint i against each other's pose and speed at slot i, with the interaction
/// term's fields (`field_params`) and floor U₀ (`floor`).
#[allow(clippy::too_many_arguments)] // the term's inputs, each used once
pub(crate) fn fixed_waypoint_term(
    horizon: &PlanHorizon,
    field_params: &ObstacleFieldParams,
    floor: f64,
    rules: RoleRules,
    req: &PlanRequest<'_>,
    others: &[Other],
    waypoints: &[[f64; 2]],
    road: &LaneRoadGeometry,
) -> FixedWaypointTerm {
    let x_scale = field_params.x_scale();
    let bases: Vec<(ObstacleField, &Other)> = others
        .iter()
        .map(|o| (base_field(field_params, x_scale, rules, req, o), o))
        .collect();
    let slots = waypoints
        .iter()
        .enumerate()
        .map(|(k, _)| {
            let t_s = slot_time_s(horizon, req, k + 1);
            bases
                .iter()
                .map(|(base, other)| {
                    let pose = other.trajectory.pose_at(t_s);
                    SlotOther {
                        field: moved_in_lane(base, road, pose.xy_m, pose.heading),
                        speed_mps: other.trajectory.speed_at(t_s),
                        shape: other.shape,
                        role: role_of(rules, other),
                    }
                })
                .collect()
        })
        .collect();
    FixedWaypointTerm::new(
        *field_params,
        req.ego_shape,
        floor,
        waypoints.to_vec(),
        slots,
    )
}
