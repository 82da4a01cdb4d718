//! Local path by gradient descent on the universal field, paper Eqs. 6–7.
//!
//! ψ_ref = atan2(F_y, F_x) (Eq. 6, the quadrant-correct arctan) and the next waypoint is
//! p + L_s (cos ψ_ref, sin ψ_ref) (Eq. 7), repeated N times. L_s = v·Δt_plan, so the spacing of
//! the waypoints encodes the speed. We integrate each step of L_s in sub-steps no longer than
//! `max_substep_m` (re-evaluating ψ_ref each time); with one sub-step this is exactly Eq. 7.
//! Sub-stepping keeps a 5 m step from jumping across the 1 m wide divider ridge.

use crate::potential_field::PotentialField;

/// N waypoints (world frame) from `start_xy_m`, each `step_m` of path length after the
/// previous one, following F_uni with the moving target. With `time_per_step_s` > 0 the
/// obstacles move at constant velocity while stepping (waypoint k is reached at k·Δt);
/// 0 keeps them where they are now, as in the paper.
pub fn local_path(
    field: &PotentialField<'_>,
    start_xy_m: [f64; 2],
    step_m: f64,
    waypoint_count: usize,
    max_substep_m: f64,
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
    use crate::road::MergeRoad;
    use crate::types::{VehicleShape, VehicleState};

    #[test]
    fn one_substep_is_eq_7_and_steps_have_length_ls() {
        let params = PlannerParams::default();
        let road = MergeRoad::default();
        let ego = VehicleState {
            x_m: 0.0,
            y_m: 2.3,
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let field = PotentialField::new(&params, &road, 0, &ego, &VehicleShape::default(), &[]);
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
    fn path_relaxes_towards_the_lane_centre() {
        let params = PlannerParams::default();
        let road = MergeRoad::default();
        let ego = VehicleState {
            x_m: 0.0,
            y_m: 2.4,
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let field = PotentialField::new(&params, &road, 0, &ego, &VehicleShape::default(), &[]);
        let path = local_path(&field, [0.0, 2.4], 5.0, 20, 1.0, 0.0);
        let centre = road.lane_center_y_m(crate::road::Lane::Lower);
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
