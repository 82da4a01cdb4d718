//! Every limit mergesim enforces, in one table: the allowed range of each scenario value (from
//! the bound tables the validators check, so the documentation cannot drift from the code), the
//! consistency rules between values, and the limits on runs, threads and work.
//!
//! `merge_sim limits` prints [`markdown`]; the README's "Limits" section is its output, and a
//! test keeps the two equal.

use mergesim_types::bounds::{Bound, markdown_rows};
use mergesim_types::lanes::{CURVED_MERGE_RADIUS_M, ON_RAMP_BOUNDS};
use mergesim_types::{MERGE_SECTION_LENGTH_M, ROAD_BOUNDS};
use planner::params::{MAX_WAYPOINTS, MIN_WAYPOINTS, PLANNER_BOUNDS};
use planner::sequencing::SEQUENCING_BOUNDS;
use scenarios::scenario::ROAD_END_SPEED_ALLOWANCE;
use sim::config::{
    MAX_PAIR_CHECKS, MAX_PLANNING_CYCLES, MAX_VEHICLE_STEPS, MAX_VEHICLES, SIM_BOUNDS,
    VEHICLE_BOUNDS,
};
use sim::idm::IDM_BOUNDS;
use sim::mobil::MOBIL_BOUNDS;
use sim::safety::SAFETY_BOUNDS;
use sim::shield::rss_rules::RSS_BOUNDS;
use sim::v2v::V2V_BOUNDS;
use vehicles::tracker::TRACKER_BOUNDS;

/// The scenario tables and their bounds, in the order of a scenario file.
pub fn scenario_tables() -> Vec<(&'static str, &'static [Bound])> {
    vec![
        ("sim", SIM_BOUNDS),
        ("sim.road", ROAD_BOUNDS),
        ("sim.lane_road.on_ramp", ON_RAMP_BOUNDS),
        ("sim.planner", PLANNER_BOUNDS),
        ("sim.planners.pf-iso-seq", SEQUENCING_BOUNDS),
        ("sim.tracker", TRACKER_BOUNDS),
        ("sim.safety", SAFETY_BOUNDS),
        ("sim.v2v", V2V_BOUNDS),
        ("sim.idm", IDM_BOUNDS),
        ("sim.mobil", MOBIL_BOUNDS),
        ("sim.rss", RSS_BOUNDS),
        ("[vehicles]", VEHICLE_BOUNDS),
        ("traffic.<stream>", scenarios::traffic::TRAFFIC_BOUNDS),
    ]
}

/// The rules between values and the limits on work, as `(what, limit)` rows.
pub fn other_limits() -> Vec<(String, String)> {
    let [merge_min_m, merge_max_m] = MERGE_SECTION_LENGTH_M;
    vec![
        (
            "vehicles per scenario".into(),
            format!("1 to {MAX_VEHICLES}"),
        ),
        (
            "`[sim]` periods (`planner_period_s`, `log_period_s`, `field_log_period_s`, \
             `safety_period_s`) and `duration_s`"
                .into(),
            "at least one physics step `dt_s`".into(),
        ),
        (
            "`[sim.road]` order".into(),
            "`start_x_m` < `merge_start_x_m` < `merge_end_x_m` < `end_x_m`".into(),
        ),
        (
            "merge section `merge_end_x_m − merge_start_x_m`".into(),
            format!("{merge_min_m} to {merge_max_m} m"),
        ),
        (
            "`[sim.lane_road]` `curved_merge.radius_m`".into(),
            format!(
                "absolute radius {} to {} m, and at least the road's length / 6",
                CURVED_MERGE_RADIUS_M[0], CURVED_MERGE_RADIUS_M[1]
            ),
        ),
        (
            "`[sim.lane_road]` lanes".into(),
            "consistent (ids, links, widths > 0, ≥ 2 distinct vertices, turns ≤ 90°); \
             `on_ramp.main_length_m` past the acceleration lane's end"
                .into(),
        ),
        (
            "CommonRoad file (`merge_sim commonroad dump`)".into(),
            format!(
                "at most {} MiB, {} lanelets, {} obstacles, {} trajectory states per obstacle",
                mergesim_commonroad::MAX_FILE_BYTES >> 20,
                mergesim_commonroad::MAX_LANELETS,
                mergesim_commonroad::MAX_OBSTACLES,
                mergesim_commonroad::MAX_STATES_PER_OBSTACLE
            ),
        ),
        (
            "OpenDRIVE file (`merge_sim opendrive dump`)".into(),
            format!(
                "at most {} MiB, {} drivable lanes, every lane within {} km of the origin",
                mergesim_opendrive::MAX_FILE_BYTES >> 20,
                mergesim_opendrive::MAX_LANES,
                mergesim_opendrive::MAX_COORDINATE_M / 1000.0
            ),
        ),
        (
            "`[sim.idm]` decelerations".into(),
            "`comfortable_decel_mps2` ≤ `max_decel_mps2`".into(),
        ),
        (
            "`[sim.rss]` braking".into(),
            "`brake_min_mps2` ≤ `brake_max_mps2`".into(),
        ),
        (
            "scenario file".into(),
            format!(
                "a regular file of at most {} MiB",
                scenarios::scenario::MAX_SCENARIO_BYTES >> 20
            ),
        ),
        (
            "`[sim.planner]` `waypoint_count`".into(),
            format!("whole number, {MIN_WAYPOINTS} to {MAX_WAYPOINTS}"),
        ),
        (
            "`[[vehicles]]` `x_m`".into(),
            "on the road: in [`start_x_m`, `end_x_m`]; on a `[sim.lane_road]`, the arc length \
             along its lane, in [0, the lane's length]"
                .into(),
        ),
        (
            "`[[vehicles]]` body at spawn".into(),
            "on the road surface (between the edges, within its length), not overlapping \
             another body, a lower-lane front before `merge_end_x_m` — over the whole \
             randomisation box; on a `[sim.lane_road]`, its corners on the lanes and no \
             overlap (oriented boxes)"
                .into(),
        ),
        (
            "road length".into(),
            format!(
                "every vehicle's front + `duration_s` × (its highest initial, target or \
                 prescribed speed, randomisation included) × {} ≤ `end_x_m`; on a \
                 `[sim.lane_road]`, ≤ the lanes ahead of it to their open end (on along the \
                 lane it merges into where its own ends)",
                1.0 + ROAD_END_SPEED_ALLOWANCE
            ),
        ),
        (
            "`[randomise]`".into(),
            "`uniform = [lo, hi]` / `clip = [lo, hi]`: exactly two finite numbers, lo ≤ hi; \
             every value the box can draw must satisfy the ranges above (checked at both \
             corners)"
                .into(),
        ),
        (
            "`[traffic.<stream>]`".into(),
            format!(
                "`flow_vph = {{ uniform = [lo, hi] }}`: exactly two numbers, lo ≤ hi; `lanes`: at \
                 least one, none twice; `rear_x_m` < `front_x_m`; the mean headway at `hi`, \
                 3600 · lanes / hi, at least `min_headway_s`; the densest instance (every \
                 headway at `min_headway_s`) at most {MAX_VEHICLES} vehicles with the listed \
                 ones, and valid like listed vehicles (on the road, no overlap, work per run); a \
                 listed vehicle in a stream's lane outside its window widened by `speed_mps` × \
                 `min_headway_s`, and not named `<stream>_…`"
            ),
        ),
        (
            "work per run: vehicles × `duration_s` / `dt_s`".into(),
            format!("≤ {MAX_VEHICLE_STEPS:.0e} vehicle physics steps"),
        ),
        (
            "work per run: vehicles × `duration_s` / `planner_period_s`".into(),
            format!("≤ {MAX_PLANNING_CYCLES:.0e} planning cycles"),
        ),
        (
            "work per run: vehicle pairs × `duration_s` / `safety_period_s`".into(),
            format!("≤ {MAX_PAIR_CHECKS:.0e} safety pair checks"),
        ),
        (
            "`sweep --runs`".into(),
            format!("1 to {}", crate::sweep::MAX_RUNS),
        ),
        (
            "`grid --runs` (per cell)".into(),
            format!("0 to {}", crate::grid::MAX_GRID_RUNS),
        ),
        (
            "`study`: cells × planners × `instances.n`".into(),
            format!(
                "{} to {} runs",
                2 * crate::study::plan::MIN_INSTANCES,
                crate::study::plan::MAX_STUDY_RUNS
            ),
        ),
        (
            "`--threads`".into(),
            format!("1 to {}", crate::sweep::MAX_THREADS),
        ),
        (
            "`--seed`, sweep seeds".into(),
            "0 to 2^64 − 1, decimal or `0x` hex; written in JSON and CSV as `0x` and 16 hex \
             digits (exact in every reader, pandas included)"
                .into(),
        ),
    ]
}

/// The whole table as Markdown.
pub fn markdown() -> String {
    let mut text = String::from(
        "Scenario values (a value must be finite and lie in its range; `(`/`)` exclude the \
         end):\n\n| field | allowed range |\n|---|---|\n",
    );
    for (table, bounds) in scenario_tables() {
        text.push_str(&markdown_rows(table, bounds));
    }
    text.push_str("\nRules between values, and limits on work:\n\n| what | limit |\n|---|---|\n");
    for (what, limit) in other_limits() {
        text.push_str(&format!("| {what} | {limit} |\n"));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bound_appears_once_per_table() {
        let text = markdown();
        for (table, bounds) in scenario_tables() {
            for b in bounds {
                let row = format!("| `[{table}]` `{}` | {} |", b.field, b.range_text());
                assert_eq!(text.matches(&row).count(), 1, "{row}");
            }
        }
    }
}
