//! The input of one planning cycle and its validation (every number finite, shapes positive).

use crate::error::PlannerError;
use mergesim_types::{Neighbour, SharedLocalPath, VehicleId, VehicleShape, VehicleState};

/// The input of one planning cycle.
#[derive(Clone, Copy, Debug)]
pub struct PlanRequest<'a> {
    /// Planning time (s).
    pub time_s: f64,
    /// The planning vehicle.
    pub ego_id: VehicleId,
    /// Its state.
    pub ego: VehicleState,
    /// Its footprint and braking.
    pub ego_shape: VehicleShape,
    /// V_target (m/s).
    pub target_speed_mps: f64,
    /// Tire–road friction μ.
    pub mu: f64,
    /// Other vehicles' current states (perception): obstacle fields of Eq. 4.
    pub neighbours: &'a [Neighbour],
    /// Fresh SLPs received over V2V (PF-ISO uses them).
    pub shared_paths: &'a [SharedLocalPath],
}

fn non_finite(what: &str) -> PlannerError {
    PlannerError::NonFinite { what: what.into() }
}

fn check_state(state: &VehicleState, what: &str) -> Result<(), PlannerError> {
    let values = [state.x_m, state.y_m, state.yaw_rad, state.speed_mps];
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(non_finite(what))
    }
}

fn check_shape(shape: &VehicleShape, what: &str) -> Result<(), PlannerError> {
    let fields = [
        ("length_m", shape.length_m),
        ("width_m", shape.width_m),
        ("wheelbase_m", shape.wheelbase_m),
        ("max_brake_decel_mps2", shape.max_brake_decel_mps2),
    ];
    for (name, value) in fields {
        if !value.is_finite() {
            return Err(non_finite(&format!("{what}.{name}")));
        }
        if value <= 0.0 {
            return Err(PlannerError::invalid(
                format!("{what}.{name}"),
                value,
                "must be > 0",
            ));
        }
    }
    Ok(())
}

/// Checks a request: every number finite, shapes positive, μ > 0, V_target ≥ 0.
pub fn validate_request(req: &PlanRequest<'_>) -> Result<(), PlannerError> {
    if !req.time_s.is_finite() {
        return Err(non_finite("request.time_s"));
    }
    check_state(&req.ego, "request.ego")?;
    check_shape(&req.ego_shape, "request.ego_shape")?;
    if !req.target_speed_mps.is_finite() {
        return Err(non_finite("request.target_speed_mps"));
    }
    if req.target_speed_mps < 0.0 {
        return Err(PlannerError::invalid(
            "request.target_speed_mps",
            req.target_speed_mps,
            "must be >= 0",
        ));
    }
    if !req.mu.is_finite() {
        return Err(non_finite("request.mu"));
    }
    if req.mu <= 0.0 {
        return Err(PlannerError::invalid("request.mu", req.mu, "must be > 0"));
    }
    for n in req.neighbours {
        check_state(&n.state, &format!("neighbour {}", n.id))?;
        check_shape(&n.shape, &format!("neighbour {}.shape", n.id))?;
    }
    for m in req.shared_paths {
        let what = format!("shared path of {}", m.vehicle_id);
        if !(m.stamp_s.is_finite() && m.speed_mps.is_finite()) {
            return Err(non_finite(&what));
        }
        check_shape(&m.shape, &format!("{what}.shape"))?;
        if m.waypoints
            .iter()
            .any(|w| !(w.t_s.is_finite() && w.x_m.is_finite() && w.y_m.is_finite()))
        {
            return Err(non_finite(&what));
        }
    }
    Ok(())
}
