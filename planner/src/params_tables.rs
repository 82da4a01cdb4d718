//! The potential-field planners' parameter tables: views on the one
//! [`PlannerParams`](crate::params::PlannerParams).
//!
//! Every PF planner keeps one `PlannerParams` inside (results do not depend on how a value
//! was written). A scenario writes its fields in one of three tables, each field in exactly
//! one, chosen by which planners read it (`grep -rn params.FIELD planner/src`):
//!
//! | table | read by | fields |
//! |---|---|---|
//! | `pf` (alias `[sim.planner]`) | every PF planner | the path field (Eqs. 1–9), the speed problem of Eq. 10 and its solver (every PF planner but PF-CS), prediction, following, stop and go, fallback |
//! | `pf-iso` | PF-ISO, PF-ISO-PRED | the interaction term of Eq. 10 (`interaction_*`), `v2v_loss_fallback` |
//! | `pf-sp` | PF-SP (and PF-ISO's V2V-loss fallback, which plans as PF-SP) | `risk_weight` |
//!
//! A planner accepts the keys of `pf` and of its own table ([`tables_of`]); a key of another
//! planner's table is refused naming that table ([`check_key`]).

use crate::planner_kind::PlannerKind;

/// The table every PF planner reads (today's `[sim.planner]`, kept as its alias).
pub const PF_TABLE: &str = "pf";
/// The table only PF-ISO and PF-ISO-PRED read.
pub const PF_ISO_TABLE: &str = "pf-iso";
/// The table only PF-SP reads (PF-ISO's V2V-loss fallback plans as PF-SP, with it).
pub const PF_SP_TABLE: &str = "pf-sp";
/// Every PF table, in the order they are applied (they are disjoint, so the order does not
/// change the result).
pub const PF_TABLES: [&str; 3] = [PF_TABLE, PF_ISO_TABLE, PF_SP_TABLE];

/// The fields of the `pf-iso` table: the interaction term of Eq. 10 and what PF-ISO does
/// without V2V.
pub const PF_ISO_FIELDS: &[&str] = &[
    "interaction_weight",
    "interaction_floor",
    "interaction_time_gap_s",
    "interaction_epsilon",
    "interaction_lateral_safety_m",
    "interaction_fraction_at_min_distance",
    "interaction_slp_reading",
    "interaction_rear_only",
    "interaction_slows_only",
    "v2v_loss_fallback",
];

/// The fields of the `pf-sp` table: the weight of PF-SP's risk term.
pub const PF_SP_FIELDS: &[&str] = &["risk_weight"];

/// Every field of [`PlannerParams`](crate::params::PlannerParams), in declaration order (a unit test
/// checks it against the struct's serde form).
pub const ALL_FIELDS: &[&str] = &[
    "attractive_gain_per_m2",
    "target_lookahead_m",
    "lane_amplitude",
    "lane_sigma_m",
    "edge_gain_m2",
    "edge_clamp_distance_m",
    "obstacle_amplitude",
    "obstacle_epsilon",
    "obstacle_lateral_safety_m",
    "obstacle_fraction_at_min_distance",
    "obstacle_time_gap_s",
    "ego_mass_factor",
    "other_mass_factor",
    "obstacle_heading_form",
    "obstacle_min_distance_length",
    "obstacle_min_distance_by_side",
    "obstacle_lateral_form",
    "waypoint_count",
    "step_time_s",
    "min_step_m",
    "predict_obstacles_in_path",
    "lane_end_walls",
    "max_substep_m",
    "substep_max_turn_rad",
    "cubic_origin_weight",
    "cubic_max_offset_m",
    "cubic_max_heading_rad",
    "cubic_max_curvature_per_m",
    "cubic_max_curvature_rate_per_m2",
    "speed_limit_mps",
    "min_speed_mps",
    "travel_time_weight",
    "speed_deviation_weight",
    "interaction_weight",
    "interaction_floor",
    "interaction_time_gap_s",
    "interaction_epsilon",
    "interaction_lateral_safety_m",
    "interaction_fraction_at_min_distance",
    "interaction_slp_reading",
    "roles_from_order_now",
    "interaction_rear_only",
    "interaction_slows_only",
    "trust_region_mps",
    "max_scp_iterations",
    "scp_relative_tolerance",
    "scp_stall_trust_region_mps",
    "scp_step_tolerance_mps",
    "accel_bound_enabled",
    "max_accel_mps2",
    "jerk_bound_enabled",
    "max_jerk_mps3",
    "solver_max_iterations",
    "solver_tolerance",
    "speed_program",
    "max_shared_path_age_s",
    "prediction",
    "risk_weight",
    "v2v_loss_fallback",
    "following_reaction_s",
    "following_standstill_gap_m",
    "following_lateral_margin_m",
    "stop_and_go_speed_mps",
    "fallback_decel_mps2",
];

/// The table that holds `field`, or `None` if `PlannerParams` has no such field.
pub fn table_of_field(field: &str) -> Option<&'static str> {
    if PF_ISO_FIELDS.contains(&field) {
        Some(PF_ISO_TABLE)
    } else if PF_SP_FIELDS.contains(&field) {
        Some(PF_SP_TABLE)
    } else if ALL_FIELDS.contains(&field) {
        Some(PF_TABLE)
    } else {
        None
    }
}

/// The tables planner `kind` reads: `pf`, then its own if it has one.
pub fn tables_of(kind: PlannerKind) -> &'static [&'static str] {
    match kind {
        PlannerKind::PfCs | PlannerKind::PfSpEq10 => &[PF_TABLE],
        PlannerKind::PfSp => &[PF_TABLE, PF_SP_TABLE],
        PlannerKind::PfIso | PlannerKind::PfIsoPred => &[PF_TABLE, PF_ISO_TABLE],
    }
}

/// Whether `key` may be written in table `table` (one of [`PF_TABLES`]); the error says why
/// not: an unknown field, or the table that holds it ("`interaction_weight` belongs to
/// pf-iso's table").
pub fn check_key(table: &str, key: &str) -> Result<(), String> {
    match table_of_field(key) {
        None => Err(format!(
            "unknown key `{key}`: not a parameter of the potential-field planners \
             (docs/parameters.md lists each table's fields)"
        )),
        Some(owner) if owner != table => Err(format!(
            "`{key}` belongs to {owner}'s table ([sim.planners.{owner}]), not {table}'s"
        )),
        Some(_) => Ok(()),
    }
}

/// Whether `key` may be written in the `params` of a vehicle driven by `kind` (the keys of
/// the tables it reads, [`tables_of`]).
pub fn check_vehicle_key(kind: PlannerKind, key: &str) -> Result<(), String> {
    match table_of_field(key) {
        None => check_key(PF_TABLE, key),
        Some(owner) if !tables_of(kind).contains(&owner) => Err(format!(
            "`{key}` belongs to {owner}'s table ([sim.planners.{owner}]), which {} does not read",
            kind.name()
        )),
        Some(_) => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;

    #[test]
    fn all_fields_are_the_structs_fields_and_each_is_in_one_table() {
        let value = serde_json::to_value(PlannerParams::default()).unwrap();
        let keys: Vec<&str> = value
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut all: Vec<&str> = ALL_FIELDS.to_vec();
        all.sort_unstable();
        let mut keys_sorted = keys.clone();
        keys_sorted.sort_unstable();
        assert_eq!(all, keys_sorted);
        for field in PF_ISO_FIELDS.iter().chain(PF_SP_FIELDS) {
            assert!(ALL_FIELDS.contains(field), "{field}");
        }
    }

    #[test]
    fn keys_of_another_table_are_refused_naming_their_owner() {
        assert!(check_key("pf", "waypoint_count").is_ok());
        assert!(check_key("pf-iso", "interaction_weight").is_ok());
        let e = check_key("pf", "interaction_weight").unwrap_err();
        assert!(e.contains("belongs to pf-iso's table"), "{e}");
        let e = check_key("pf-iso", "risk_weight").unwrap_err();
        assert!(e.contains("belongs to pf-sp's table"), "{e}");
        assert!(
            check_key("pf", "w3")
                .unwrap_err()
                .contains("unknown key `w3`")
        );
        assert!(check_vehicle_key(PlannerKind::PfIsoPred, "interaction_weight").is_ok());
        assert!(check_vehicle_key(PlannerKind::PfIso, "waypoint_count").is_ok());
        let e = check_vehicle_key(PlannerKind::PfCs, "risk_weight").unwrap_err();
        assert!(e.contains("pf-sp's table") && e.contains("pf-cs"), "{e}");
    }
}
