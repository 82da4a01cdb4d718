//! Tests of the planner parameters and their bounds.

use super::*;

#[test]
fn every_numeric_field_has_exactly_one_bound() {
    let values = PlannerParams::default().bounded_values();
    assert_eq!(values.len(), PLANNER_BOUNDS.len());
    for (field, _) in &values {
        assert_eq!(
            PLANNER_BOUNDS.iter().filter(|b| b.field == *field).count(),
            1,
            "{field}"
        );
    }
}

#[test]
fn work_and_magnitudes_are_bounded() {
    for (field, value) in [
        ("max_scp_iterations", 1000.0),
        ("step_time_s", 1e300),
        ("min_step_m", 1e300),
        ("waypoint_count", 1e6),
    ] {
        let mut params = PlannerParams::default();
        match field {
            "max_scp_iterations" => params.max_scp_iterations = value as usize,
            "step_time_s" => params.step_time_s = value,
            "min_step_m" => params.min_step_m = value,
            _ => params.waypoint_count = value as usize,
        }
        let err = params.validate().unwrap_err().to_string();
        assert!(err.contains(field), "{err}");
    }
}

#[test]
fn default_is_valid() {
    PlannerParams::default().validate().unwrap();
}

#[test]
fn too_few_waypoints_is_rejected_by_name() {
    let params = PlannerParams {
        waypoint_count: 3,
        ..PlannerParams::default()
    };
    let err = params.validate().unwrap_err().to_string();
    assert!(err.contains("waypoint_count"), "{err}");
}

#[test]
fn nan_is_rejected_by_name() {
    let params = PlannerParams {
        lane_sigma_m: f64::NAN,
        ..PlannerParams::default()
    };
    let err = params.validate().unwrap_err().to_string();
    assert!(err.contains("lane_sigma_m"), "{err}");
}

#[test]
fn unknown_fields_are_rejected() {
    let text = r#"{"waypoint_count": 10, "no_such_field": 1.0}"#;
    assert!(serde_json::from_str::<PlannerParams>(text).is_err());
    let partial: PlannerParams = serde_json::from_str(r#"{"waypoint_count": 10}"#).unwrap();
    assert_eq!(partial.waypoint_count, 10);
    assert_eq!(partial.step_time_s, PlannerParams::default().step_time_s);
}
