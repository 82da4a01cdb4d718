//! Local path by gradient descent on the universal field, paper Eqs. 6–7.
//!
//! ψ_ref = atan2(F_y, F_x) (Eq. 6, the quadrant-correct arctan) and the next waypoint is
//! p + L_s (cos ψ_ref, sin ψ_ref) (Eq. 7), repeated N times. L_s = v·Δt_plan, so the spacing of
//! the waypoints encodes the speed. We integrate each step of L_s in sub-steps no longer than
//! `max_substep_m` (re-evaluating ψ_ref each time); with one sub-step this is exactly Eq. 7.
//! Sub-stepping keeps a 5 m step from jumping across the 1 m wide divider ridge.
//!
//! Fixed sub-steps are not enough where the field is stiff across the path: against the road
//! edge's clamped wall (slope ξ/d_c³ = 10 per metre with the defaults), squeezed there by the
//! field of a vehicle ahead, a normalised step of h metres is only stable while h·k ≲ 1 for the
//! lateral stiffness k, so 1 m sub-steps bounce off the wall (ψ_ref flipping between +0.5 and
//! −1.47 rad on consecutive sub-steps). Where a waypoint lands in that zig-zag depends chaotically
//! on the start pose, so consecutive plans (0.1 s apart) moved their far waypoints by ±0.5 m, the
//! cubic fit of Eq. 9 carried that into the near path (±0.2 m at the tracker's look-ahead) and
//! the follower's yaw rate chattered at ±0.03 rad/s. `local_path_adaptive` therefore halves a
//! sub-step while ψ_ref turns by more than a set angle across it: an explicit streamline
//! integrator with step-size control, which leaves the path unchanged where the field is smooth.

use crate::potential_field::PotentialField;
use mergesim_types::angle::wrap_angle_rad;

/// N waypoints (world frame) from `start_xy_m`, each `step_m` of path length after the
/// previous one, following F_uni with the moving target. With `time_per_step_s` > 0 the
/// obstacles move at constant velocity while stepping (waypoint k is reached at k·Δt);
/// 0 keeps them where they are now, as in the paper.
///
/// Fixed sub-steps: `local_path_adaptive` with no turn limit.
pub fn local_path(
    field: &PotentialField<'_>,
    start_xy_m: [f64; 2],
    step_m: f64,
    waypoint_count: usize,
    max_substep_m: f64,
    time_per_step_s: f64,
) -> Vec<[f64; 2]> {
    local_path_adaptive(
        field,
        start_xy_m,
        step_m,
        waypoint_count,
        max_substep_m,
        0.0,
        time_per_step_s,
    )
}

/// Fewest halvings of the base sub-step [`local_path_adaptive`] may make: its sub-steps are at
/// least 1/64 of the base sub-step (1.6 cm with 1 m), which bounds the work per waypoint even at
/// a stagnation point, where ψ_ref reverses however short the sub-step.
const MAX_SUBSTEP_HALVINGS: i32 = 6;

/// [`local_path`] with step-size control: each waypoint step is integrated in sub-steps of at
/// most `step_m / ⌈step_m / max_substep_m⌉` (the fixed sub-step), halved while ψ_ref at the
/// sub-step's end differs from ψ_ref at its start by more than `max_turn_rad` (down to 1/64 of
/// the fixed sub-step, which is then accepted), and doubled again after each accepted sub-step.
/// Each waypoint is still exactly `step_m` of path length after the previous one.
/// `max_turn_rad` = 0 (or not finite) gives the fixed sub-steps of [`local_path`] bit for bit.
pub(crate) fn local_path_adaptive(
    field: &PotentialField<'_>,
    start_xy_m: [f64; 2],
    step_m: f64,
    waypoint_count: usize,
    max_substep_m: f64,
    max_turn_rad: f64,
    time_per_step_s: f64,
) -> Vec<[f64; 2]> {
    let substeps = if step_m.is_finite() && max_substep_m > 0.0 {
        ((step_m / max_substep_m).ceil() as usize).clamp(1, 1000)
    } else {
        1
    };
    let h = step_m / substeps as f64;
    let mut p = start_xy_m;
    let mut waypoints = Vec::with_capacity(waypoint_count);
    if max_turn_rad > 0.0 && max_turn_rad.is_finite() && h > 0.0 && h.is_finite() {
        let h_min = h * 0.5_f64.powi(MAX_SUBSTEP_HALVINGS);
        let direction = |force: [f64; 2]| force[1].atan2(force[0]);
        let mut psi = direction(field.stepping_force_at(p[0], p[1], 0.0));
        let mut substep = h;
        for k in 0..waypoint_count {
            let mut done_m = 0.0;
            while done_m < step_m {
                let remaining_m = step_m - done_m;
                let last = substep >= remaining_m;
                let length = if last { remaining_m } else { substep };
                let (sin_psi, cos_psi) = psi.sin_cos();
                let q = [p[0] + length * cos_psi, p[1] + length * sin_psi];
                let along = if last {
                    1.0
                } else {
                    (done_m + length) / step_m
                };
                let elapsed_s = (k as f64 + along) * time_per_step_s;
                let psi_q = direction(field.stepping_force_at(q[0], q[1], elapsed_s));
                let turn = wrap_angle_rad(psi_q - psi);
                // NaN turns are accepted: the caller checks the waypoints for finiteness.
                if turn.abs() > max_turn_rad && length > h_min {
                    substep = (0.5 * length).max(h_min);
                    continue;
                }
                p = q;
                psi = psi_q;
                done_m = if last { step_m } else { done_m + length };
                substep = (2.0 * substep).min(h);
            }
            waypoints.push(p);
        }
        return waypoints;
    }
    let dt_substep = time_per_step_s / substeps as f64;
    for k in 0..waypoint_count {
        for j in 0..substeps {
            let elapsed_s = (k * substeps + j) as f64 * dt_substep;
            let force = field.stepping_force_at(p[0], p[1], elapsed_s);
            let psi_ref = force[1].atan2(force[0]);
            let (sin_psi, cos_psi) = psi_ref.sin_cos();
            p = [p[0] + h * cos_psi, p[1] + h * sin_psi];
        }
        waypoints.push(p);
    }
    waypoints
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;
    use mergesim_types::MergeRoad;
    use mergesim_types::{VehicleShape, VehicleState};

    #[test]
    fn one_substep_is_eq_7_and_steps_have_length_ls() {
        let params = PlannerParams::default();
        let merge = MergeRoad::default();
        let road = crate::lane_road_field::LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = VehicleState {
            x_m: 0.0,
            y_m: 2.3,
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let field = PotentialField::new(
            &(&params).into(),
            &road,
            0,
            &ego,
            &VehicleShape::default(),
            &[],
        );
        let path = local_path(&field, [0.0, 2.3], 5.0, 6, 10.0, 0.0);
        // Reference: Eq. 6–7 written out by hand from the force.
        let mut p = [0.0, 2.3];
        for w in &path {
            let f = field.stepping_force(p[0], p[1]);
            let norm = (f[0] * f[0] + f[1] * f[1]).sqrt();
            p = [p[0] + 5.0 * f[0] / norm, p[1] + 5.0 * f[1] / norm];
            assert!((w[0] - p[0]).abs() < 1e-12 && (w[1] - p[1]).abs() < 1e-12);
        }
    }

    #[test]
    fn adaptive_substeps_follow_the_stream_line_along_the_edge_wall() {
        // The urgent merge at t = 12 s: the follower (upper lane, 15 m/s) behind the merging
        // car, whose field squeezes its path against the road edge's wall, where 1 m sub-steps
        // bounce (ψ_ref flips between ≈ +0.5 and −1.47 rad).
        use mergesim_types::Neighbour;
        let params = PlannerParams::default();
        let merge = MergeRoad::default();
        let road = crate::lane_road_field::LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = VehicleState {
            x_m: 215.0,
            y_m: 5.85,
            yaw_rad: 0.0,
            speed_mps: 15.0,
        };
        let ahead = Neighbour {
            id: 1,
            state: VehicleState {
                x_m: 240.0,
                y_m: 4.45,
                yaw_rad: 0.03,
                speed_mps: 20.0,
            },
            shape: VehicleShape::default(),
        };
        let neighbours = [ahead];
        let field = PotentialField::new(
            &(&params).into(),
            &road,
            0,
            &ego,
            &VehicleShape::default(),
            &neighbours,
        );
        let start = [ego.x_m, ego.y_m];
        let turn = params.substep_max_turn_rad;
        let reference = local_path(&field, start, 6.0, 20, 0.01, 0.0);
        let fixed = local_path(&field, start, 6.0, 20, 1.0, 0.0);
        let adaptive = local_path_adaptive(&field, start, 6.0, 20, 1.0, turn, 0.0);
        let worst = |path: &[[f64; 2]]| {
            path.iter()
                .zip(&reference)
                .map(|(p, r)| (p[1] - r[1]).abs())
                .fold(0.0, f64::max)
        };
        assert!(worst(&fixed) > 0.3, "fixed sub-steps: {}", worst(&fixed));
        assert!(worst(&adaptive) < 0.1, "adaptive: {}", worst(&adaptive));
        // Each waypoint is still one step of path length after the previous one (the polyline
        // through the sub-steps, so the chord is at most that).
        let mut previous = start;
        for p in &adaptive {
            let chord = (p[0] - previous[0]).hypot(p[1] - previous[1]);
            assert!(chord <= 6.0 + 1e-9 && chord > 5.5, "{chord}");
            previous = *p;
        }
        // Without a turn limit it is the fixed integration, bit for bit.
        assert_eq!(
            local_path_adaptive(&field, start, 6.0, 20, 1.0, 0.0, 0.0),
            fixed
        );
    }

    #[test]
    fn path_relaxes_towards_the_lane_centre() {
        let params = PlannerParams::default();
        let merge = MergeRoad::default();
        let road = crate::lane_road_field::LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = VehicleState {
            x_m: 0.0,
            y_m: 2.4,
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let field = PotentialField::new(
            &(&params).into(),
            &road,
            0,
            &ego,
            &VehicleShape::default(),
            &[],
        );
        let path = local_path(&field, [0.0, 2.4], 5.0, 20, 1.0, 0.0);
        let centre = merge.lane_center_y_m(mergesim_types::Lane::Lower);
        let first_offset = (2.4 - centre).abs();
        let last_offset = (path[19][1] - centre).abs();
        assert!(
            last_offset < 0.3 * first_offset,
            "{last_offset} vs {first_offset}"
        );
        // Monotone along X (the pull dominates).
        assert!(path.windows(2).all(|w| w[1][0] > w[0][0]));
    }
}
