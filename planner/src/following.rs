//! PF-ISO's behaviour when V2V is lost: risk-aware speeds with a safe-following cap.
//!
//! PF-ISO's interaction term is built for *received* shared paths: declared intents with
//! per-slot roles. When a PF-ISO vehicle has no fresh shared path from anybody around it (its
//! messages are lost, or nobody near is connected) once a shared path could have arrived
//! (`max_shared_path_age_s` after its first cycle), it has no intents to negotiate with, and
//! running the interaction term on predictions lets two vehicles side by side each expect the
//! other to give way (`docs/robustness.md` measures the collisions). With
//! [`V2vLossFallback::RiskAwareFollowing`] (the `mergesim` default) such a cycle instead
//!
//! 1. plans its speeds as PF-SP does (the risk of the others' path fields at their predicted
//!    positions along its own path; the risk may only slow it down), and
//! 2. caps every speed at the *safe following speed* of Gipps (1981) behind the nearest vehicle
//!    ahead in its path corridor:
//!
//!    v_safe = −b τ + √(b² τ² + v_l² + 2 b (g − s₀)),
//!
//!    with g the bumper gap along the road, v_l the leader's speed, b = `max_accel_mps2` (the
//!    deceleration the speed optimiser itself may command; the leader is assumed to brake no
//!    harder), τ = `following_reaction_s` and s₀ = `following_standstill_gap_m`. A vehicle
//!    following at v_safe stops behind a leader that brakes at b, after reacting for τ. The
//!    cap is reached no faster than at b from the current speed (so the speed problem stays
//!    feasible).
//!
//! A vehicle is *in the corridor* when its centre is ahead of the planning vehicle's and its
//! lateral distance from the planned path is below the half-widths plus
//! `following_lateral_margin_m`, at its longitudinal position now **or where the planning vehicle
//! would reach it** (its position after the time the current closing speed needs to close the
//! bumper gap): the car it would hit by driving on, including one it is squeezing past in a
//! single lane, and one in the lane its path is about to enter. The second test matters in a
//! merge: the path reaches the target lane some tens of metres ahead, where the slower car in
//! that lane will be when the merging car catches up with it; tested only at the car's current
//! position, the cap arrived once the two were already side by side (measured in
//! `docs/robustness.md`).

use serde::{Deserialize, Serialize};

use crate::lane_road_field::LaneRoadGeometry;
use mergesim_types::{Neighbour, VehicleId, VehicleShape, VehicleState};

/// What a PF-ISO vehicle does in a cycle without any fresh shared path around it (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum V2vLossFallback {
    /// Keep the interaction term, on predictions of the others (the paper's reading: it does not
    /// say what happens without V2V).
    InteractWithPredictions,
    /// PF-SP's risk-aware speeds with the safe-following cap (our default).
    #[default]
    RiskAwareFollowing,
}

/// The numbers of the safe-following cap and its corridor (module doc), built once from
/// `PlannerParams` (`derived_params`). Not from the paper: Gipps (1981).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FollowingParams {
    /// b, the deceleration both vehicles are assumed to brake at (m/s²): the speed optimiser's
    /// own a_max (`max_accel_mps2`, the acceleration bound of Eq. 10).
    pub decel_mps2: f64,
    /// τ, reaction time before braking (s; `following_reaction_s`).
    pub reaction_s: f64,
    /// s₀, the bumper gap left at standstill (m; `following_standstill_gap_m`).
    pub standstill_gap_m: f64,
    /// Margin added to the half-widths of the corridor test (m; `following_lateral_margin_m`).
    pub lateral_margin_m: f64,
}

/// Gipps' safe speed behind a leader at bumper gap `gap_m` driving at `leader_speed_mps`
/// (module doc); 0 when even a standing start is too close.
pub fn safe_following_speed_mps(
    params: &FollowingParams,
    gap_m: f64,
    leader_speed_mps: f64,
) -> f64 {
    let b = params.decel_mps2;
    let tau = params.reaction_s;
    let room_m = gap_m - params.standstill_gap_m;
    let radicand = b * b * tau * tau + leader_speed_mps * leader_speed_mps + 2.0 * b * room_m;
    if radicand <= 0.0 {
        return 0.0;
    }
    (-b * tau + radicand.sqrt()).max(0.0)
}

/// Lateral position of the polyline `path` (world points, increasing x assumed piecewise) at
/// longitudinal position `x_m`: interpolated between the points around it, the end point's
/// beyond the end, the first point's before the start.
fn path_y_at(path: &[[f64; 2]], x_m: f64) -> Option<f64> {
    let first = path.first()?;
    if x_m <= first[0] {
        return Some(first[1]);
    }
    for pair in path.windows(2) {
        let ([x0, y0], [x1, y1]) = (pair[0], pair[1]);
        if x_m <= x1 {
            let span = x1 - x0;
            let f = if span > 1e-9 { (x_m - x0) / span } else { 1.0 };
            return Some(y0 + f * (y1 - y0));
        }
    }
    path.last().map(|p| p[1])
}

/// Bumper-to-bumper gap (m) along X from the planning vehicle to a neighbour ahead of it.
fn bumper_gap_m(ego: &VehicleState, ego_shape: &VehicleShape, n: &Neighbour) -> f64 {
    n.state.x_m - ego.x_m - 0.5 * (ego_shape.length_m + n.shape.length_m)
}

/// Where along X (m) the planning vehicle would reach the neighbour `n` ahead of it if both kept
/// their speeds: the neighbour's position after the time the closing speed needs to close the
/// bumper gap; its current position when the planning vehicle is not closing in (or already
/// overlaps it).
fn meeting_x_m(ego: &VehicleState, ego_shape: &VehicleShape, n: &Neighbour) -> f64 {
    let closing_mps = ego.speed_mps - n.state.speed_mps;
    let gap_m = bumper_gap_m(ego, ego_shape, n);
    if closing_mps <= 0.0 || gap_m <= 0.0 || !closing_mps.is_finite() || !gap_m.is_finite() {
        return n.state.x_m;
    }
    n.state.x_m + n.state.speed_mps.max(0.0) * (gap_m / closing_mps)
}

/// The vehicles ahead of `ego` (shape `ego_shape`) in its corridor along `path` (world points
/// from its position on; module doc), each as (bumper gap along X (m), speed (m/s)).
pub fn corridor_leaders(
    params: &FollowingParams,
    ego_id: VehicleId,
    ego: &VehicleState,
    ego_shape: &VehicleShape,
    neighbours: &[Neighbour],
    path: &[[f64; 2]],
) -> Vec<(f64, f64)> {
    neighbours
        .iter()
        .filter(|n| n.id != ego_id && n.state.x_m > ego.x_m)
        .filter(|n| {
            let half_widths_m = 0.5 * (ego_shape.width_m + n.shape.width_m);
            let in_corridor_at = |x_m: f64| {
                path_y_at(path, x_m).is_some_and(|y| {
                    (y - n.state.y_m).abs() < half_widths_m + params.lateral_margin_m
                })
            };
            in_corridor_at(n.state.x_m) || in_corridor_at(meeting_x_m(ego, ego_shape, n))
        })
        .map(|n| (bumper_gap_m(ego, ego_shape, n), n.state.speed_mps))
        .collect()
}

/// The safe-following cap (m/s) of a vehicle at `ego` (shape `ego_shape`) planning along
/// `path` (world points from its position on), behind the nearest neighbour in its corridor;
/// `None` when no neighbour is in it.
pub fn following_cap_mps(
    params: &FollowingParams,
    ego_id: VehicleId,
    ego: &VehicleState,
    ego_shape: &VehicleShape,
    neighbours: &[Neighbour],
    path: &[[f64; 2]],
) -> Option<f64> {
    cap_behind(
        params,
        &corridor_leaders(params, ego_id, ego, ego_shape, neighbours, path),
    )
}

/// The smallest safe-following speed behind `leaders` ((gap, speed) pairs); `None` if empty.
pub fn cap_behind(params: &FollowingParams, leaders: &[(f64, f64)]) -> Option<f64> {
    leaders
        .iter()
        .map(|&(gap_m, speed_mps)| safe_following_speed_mps(params, gap_m, speed_mps))
        .reduce(f64::min)
}

/// [`corridor_leaders`] on a road of lanes: the ego, the neighbours and the path are first
/// mapped into the frame of the ego's lane (x → s along it, y → d across it), so "ahead", the
/// bumper gap and the corridor are measured along the road, curved or not (on a straight road
/// along +x the same figures as in world coordinates).
pub fn corridor_leaders_in_lane_frame(
    params: &FollowingParams,
    road: &LaneRoadGeometry,
    ego_id: VehicleId,
    ego: &VehicleState,
    ego_shape: &VehicleShape,
    neighbours: &[Neighbour],
    path: &[[f64; 2]],
) -> Vec<(f64, f64)> {
    let lane = road.lane_index_at([ego.x_m, ego.y_m]);
    let to_frame = |p: [f64; 2]| {
        let j = road.jacobian(lane, p);
        [j.frame.s_m, j.frame.d_m]
    };
    let state_in_frame = |s: &VehicleState| {
        let [x_m, y_m] = to_frame([s.x_m, s.y_m]);
        VehicleState { x_m, y_m, ..*s }
    };
    let ego_f = state_in_frame(ego);
    let neighbours_f: Vec<Neighbour> = neighbours
        .iter()
        .map(|n| Neighbour {
            state: state_in_frame(&n.state),
            ..*n
        })
        .collect();
    let path_f: Vec<[f64; 2]> = path.iter().map(|p| to_frame(*p)).collect();
    corridor_leaders(params, ego_id, &ego_f, ego_shape, &neighbours_f, &path_f)
}

/// [`following_cap_mps`] on a road of lanes ([`corridor_leaders_in_lane_frame`]).
pub fn following_cap_in_lane_frame_mps(
    params: &FollowingParams,
    road: &LaneRoadGeometry,
    ego_id: VehicleId,
    ego: &VehicleState,
    ego_shape: &VehicleShape,
    neighbours: &[Neighbour],
    path: &[[f64; 2]],
) -> Option<f64> {
    cap_behind(
        params,
        &corridor_leaders_in_lane_frame(params, road, ego_id, ego, ego_shape, neighbours, path),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;

    fn neighbour(id: VehicleId, x_m: f64, y_m: f64, speed_mps: f64) -> Neighbour {
        Neighbour {
            id,
            state: VehicleState {
                x_m,
                y_m,
                yaw_rad: 0.0,
                speed_mps,
            },
            shape: VehicleShape::default(),
        }
    }

    #[test]
    fn gipps_speed_stops_behind_a_braking_leader() {
        let params = FollowingParams::from(&PlannerParams::default());
        let b = params.decel_mps2;
        let tau = params.reaction_s;
        for (gap_m, v_l) in [(30.0, 15.0), (10.0, 14.0), (60.0, 0.0), (3.0, 20.0)] {
            let v = safe_following_speed_mps(&params, gap_m, v_l);
            // Travelled while reacting and braking at b vs the leader's braking distance.
            let follower_m = v * tau + v * v / (2.0 * b);
            let leader_m = v_l * v_l / (2.0 * b);
            let left_m = gap_m + leader_m - follower_m;
            assert!(
                (left_m - params.standstill_gap_m).abs() < 1e-9,
                "gap {gap_m}, leader {v_l}: v {v}, leaves {left_m} m"
            );
        }
        // Closer than the standstill gap behind a standing car: stop.
        assert_eq!(safe_following_speed_mps(&params, 1.0, 0.0), 0.0);
    }

    #[test]
    fn only_vehicles_ahead_in_the_path_corridor_cap_the_speed() {
        let params = FollowingParams::from(&PlannerParams::default());
        let ego = VehicleState {
            x_m: 0.0,
            y_m: 1.75,
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let shape = VehicleShape::default();
        let straight: Vec<[f64; 2]> = (1..=20).map(|i| [8.0 * i as f64, 1.75]).collect();
        let into_upper: Vec<[f64; 2]> = (1..=20)
            .map(|i| [8.0 * i as f64, 1.75 + (0.4 * i as f64).min(3.5)])
            .collect();
        let beside = neighbour(1, 30.0, 5.25, 15.0);
        let behind = neighbour(2, -20.0, 1.75, 25.0);
        let ahead = neighbour(3, 40.0, 1.75, 10.0);
        let cap = |path: &[[f64; 2]], ns: &[Neighbour]| {
            following_cap_mps(&params, 0, &ego, &shape, ns, path)
        };
        assert_eq!(cap(&straight, &[beside, behind]), None);
        let gap_m = 40.0 - shape.length_m;
        assert_eq!(
            cap(&straight, &[beside, behind, ahead]),
            Some(safe_following_speed_mps(&params, gap_m, 10.0))
        );
        // A path into the other lane puts the car there in the corridor.
        let gap_m = 30.0 - shape.length_m;
        assert_eq!(
            cap(&into_upper, &[beside]),
            Some(safe_following_speed_mps(&params, gap_m, 15.0))
        );
    }

    #[test]
    fn a_car_in_the_lane_the_path_is_about_to_enter_caps_the_speed_where_it_would_be_reached() {
        let params = FollowingParams::from(&PlannerParams::default());
        let shape = VehicleShape::default();
        // The path stays in the lower lane for 40 m, then reaches the upper lane by x = 80 m.
        let merging: Vec<[f64; 2]> = (0..=20)
            .map(|i| {
                let x = 8.0 * i as f64;
                [x, 1.75 + ((x - 40.0) / 40.0).clamp(0.0, 1.0) * 3.5]
            })
            .collect();
        // 12 m ahead in the upper lane: where it is now the path is still in the lower lane.
        let slower = neighbour(1, 12.0, 5.25, 13.0);
        let cap = |ego_speed_mps: f64| {
            let ego = VehicleState {
                x_m: 0.0,
                y_m: 1.75,
                yaw_rad: 0.0,
                speed_mps: ego_speed_mps,
            };
            following_cap_mps(&params, 0, &ego, &shape, &[slower], &merging)
        };
        // Closing at 6 m/s: the ego reaches it after (12 − L)/6 s, by when it is at
        // x = 12 + 13 (12 − L)/6 ≈ 28 m, still on the lower-lane part of the path: no cap.
        assert_eq!(cap(19.0), None);
        // Closing at 1 m/s it is reached at x ≈ 12 + 13 (12 − L) > 80 m, in the upper lane.
        let gap_m = 12.0 - shape.length_m;
        assert_eq!(
            cap(14.0),
            Some(safe_following_speed_mps(&params, gap_m, 13.0))
        );
        // Not closing in: it stays ahead, where the path is still in the lower lane.
        assert_eq!(cap(12.0), None);
    }
}
