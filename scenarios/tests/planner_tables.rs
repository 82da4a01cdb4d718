//! Each planner's own parameter tables in a scenario: `[sim.planners.NAME]` (the PF planners'
//! `pf`, alias `[sim.planner]`, `pf-iso` and `pf-sp`) and a vehicle's
//! `driver = { planner = "NAME", params = { … } }`; each refusal names the file, the line and
//! the field.

use std::sync::Arc;

use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};
use scenarios::scenario::{Scenario, ScenarioError};
use sim::registry::{BehaviourRegistry, FactoryInput};
use sim::{ParamsError, PlannerParameters};

const URGENT: &str = include_str!("../builtin/urgent_merge.toml");
const EGO_DRIVER: &str = "driver = { planner = \"pf-iso\" }";

/// The urgent merge with `tables` appended and the ego's driver replaced by `ego_driver`.
fn text_with(tables: &str, ego_driver: Option<&str>) -> String {
    let mut text = URGENT.to_string();
    if let Some(driver) = ego_driver {
        text = text.replacen(EGO_DRIVER, driver, 1);
    }
    text + "\n" + tables
}

fn load(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_toml(text, "s.toml")
}

/// The 1-based line of the first line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{needle:?} not in the text"))
}

/// Asserts `e` is a refusal of `s.toml` at `line` naming `field`, its message holding `words`.
fn assert_refused(e: ScenarioError, line: usize, field: &str, words: &[&str]) {
    let shown = e.to_string();
    match &e {
        ScenarioError::Invalid {
            origin,
            line: l,
            field: f,
            ..
        } => {
            assert_eq!(origin, "s.toml", "{shown}");
            assert_eq!(l.0, Some(line), "{shown}");
            assert_eq!(f.as_deref(), Some(field), "{shown}");
        }
        other => panic!("not an Invalid error: {other:?}"),
    }
    assert!(
        shown.starts_with(&format!("s.toml, line {line}: ")),
        "{shown}"
    );
    for word in words {
        assert!(shown.contains(word), "{word:?} not in {shown}");
    }
}

#[test]
fn the_pf_tables_are_views_on_the_one_parameter_struct_and_the_old_form_reads_the_same() {
    let new = load(&text_with(
        "[sim.planners.pf]\nwaypoint_count = 16\n\n[sim.planners.pf-iso]\ninteraction_weight = 9.0\n\n[sim.planners.pf-sp]\nrisk_weight = 30.0\n",
        None,
    ))
    .unwrap();
    let old = load(&text_with(
        "[sim.planner]\nwaypoint_count = 16\ninteraction_weight = 9.0\nrisk_weight = 30.0\n",
        None,
    ))
    .unwrap();
    assert_eq!(new.sim.planner.waypoint_count, 16);
    assert_eq!(new.sim.planner.interaction_weight, 9.0);
    assert_eq!(new.sim.planner.risk_weight, 30.0);
    assert_eq!(new.sim.planner, old.sim.planner);
    assert!(new.sim.planners.is_empty(), "the PF tables are merged");
    // --params keeps the tables' values on top of the other set.
    let paper = new
        .with_parameter_set(planner::ParameterSet::Paper)
        .unwrap();
    assert_eq!(paper.sim.planner.interaction_weight, 9.0);
    assert!(!paper.sim.planner.predict_obstacles_in_path);
}

#[test]
fn an_unknown_key_is_refused_with_file_line_and_field() {
    let text = text_with("[sim.planners.pf-iso]\nw3 = 1.0\n", None);
    let e = load(&text).unwrap_err();
    assert_refused(
        e,
        line_of(&text, "w3 = "),
        "planners.pf-iso.w3",
        &["unknown key `w3`"],
    );
}

#[test]
fn a_key_of_another_planner_s_table_is_refused_naming_its_owner() {
    let text = text_with("[sim.planners.pf]\ninteraction_weight = 6.0\n", None);
    let e = load(&text).unwrap_err();
    assert_refused(
        e,
        line_of(&text, "interaction_weight = 6.0"),
        "planners.pf.interaction_weight",
        &["`interaction_weight` belongs to pf-iso's table"],
    );
    // A table named after a PF planner that reads another table.
    let text = text_with(
        "[sim.planners.pf-iso-pred]\ninteraction_weight = 6.0\n",
        None,
    );
    let e = load(&text).unwrap_err();
    assert_refused(
        e,
        line_of(&text, "[sim.planners.pf-iso-pred]"),
        "planners.pf-iso-pred",
        &["[sim.planners.pf-iso]"],
    );
}

#[test]
fn an_out_of_range_value_in_a_pf_table_is_refused_at_its_line() {
    let text = text_with("[sim.planners.pf-sp]\nrisk_weight = -1.0\n", None);
    let e = load(&text).unwrap_err();
    assert_refused(
        e,
        line_of(&text, "risk_weight = -1.0"),
        "planners.pf-sp.risk_weight",
        // The message names the table the file wrote, not the alias `planner.`.
        &["planners.pf-sp.risk_weight = -1"],
    );
}

#[test]
fn a_vehicle_s_params_give_its_planner_its_own_values() {
    let text = text_with(
        "[sim.planners.pf-iso]\ninteraction_weight = 9.0\n",
        Some(
            "driver = { planner = \"pf-iso\", params = { interaction_weight = 6.0, waypoint_count = 16 } }",
        ),
    );
    let scenario = load(&text).unwrap();
    // The scenario-level value stays the table's; the ego's own table is kept apart.
    assert_eq!(scenario.sim.planner.interaction_weight, 9.0);
    let own = scenario.vehicles[0].driver.params().unwrap();
    assert_eq!(scenario.vehicles[0].name, "ego");
    assert_eq!(own["interaction_weight"].as_float(), Some(6.0));
    assert_eq!(scenario.vehicles[1].driver.params(), None);
    // The ego's planner gets the scenario's values with its own on top.
    let registry = BehaviourRegistry::builtin();
    let parsed = registry
        .parse_params("pf-iso", &scenario.sim, Some(own))
        .unwrap()
        .unwrap();
    let params = parsed
        .downcast_ref::<planner::params::PlannerParams>()
        .unwrap();
    assert_eq!(params.interaction_weight, 6.0);
    assert_eq!(params.waypoint_count, 16);
    assert_eq!(params.step_time_s, scenario.sim.planner.step_time_s);
    // Written back as TOML, it reads back the same.
    let again = load(&scenario.to_toml().unwrap()).unwrap();
    assert_eq!(again.vehicles, scenario.vehicles);
    assert_eq!(again.sim.planner, scenario.sim.planner);
}

#[test]
fn a_vehicle_s_bad_params_are_refused_at_their_line() {
    let cases = [
        ("params = { w3 = 1.0 }", "w3", "unknown key `w3`"),
        (
            "params = { risk_weight = 1.0 }",
            "risk_weight",
            "belongs to pf-sp's table",
        ),
        (
            "params = { interaction_weight = -2.0 }",
            "interaction_weight",
            "interaction_weight",
        ),
    ];
    for (params, key, words) in cases {
        let driver = format!("driver = {{ planner = \"pf-iso\", {params} }}");
        let text = text_with("", Some(&driver));
        let e = load(&text).unwrap_err();
        assert_refused(
            e,
            line_of(&text, params),
            &format!("vehicles[ego].driver.params.{key}"),
            &[words],
        );
    }
    // Params without a planner.
    let text = URGENT.replacen(
        EGO_DRIVER,
        "driver = { prescribed = { path_planner = \"pf-iso\", speed_profile = [[0.0, 20.0]] }, params = { waypoint_count = 16 } }",
        1,
    );
    let e = load(&text).unwrap_err();
    let line = line_of(&text, "params = { waypoint_count");
    assert_refused(
        e,
        line,
        "vehicles[#0].driver.params",
        &["params go with a planner"],
    );
}

/// A user's planner parameters.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct CruiseParams {
    gap_m: f64,
    label: String,
}

impl PlannerParameters for CruiseParams {
    fn validate(&self) -> Result<(), ParamsError> {
        if (0.0..=100.0).contains(&self.gap_m) {
            Ok(())
        } else {
            Err(ParamsError::at(
                "gap_m",
                format!("{} m is outside [0, 100] m", self.gap_m),
            ))
        }
    }
}

struct Never;
impl Behaviour for Never {
    fn plan(&mut self, _: &Observation<'_>) -> Result<Decision, BehaviourError> {
        Err("not run".into())
    }
}

fn user_registry() -> BehaviourRegistry {
    let mut registry = BehaviourRegistry::builtin();
    registry
        .register_with_params("cruise", |_: &FactoryInput<'_>, _: &CruiseParams| {
            Ok(Box::new(Never) as Box<dyn Behaviour>)
        })
        .unwrap();
    registry
        .register(
            "bare",
            Arc::new(|_: &FactoryInput<'_>| Ok(Box::new(Never) as Box<dyn Behaviour>)),
        )
        .unwrap();
    registry
}

#[test]
fn a_user_planner_s_table_is_read_by_its_own_type_and_checked_with_lines() {
    let text = text_with(
        "[sim.planners.cruise]\ngap_m = 12.0\nlabel = \"scenario\"\n",
        Some("driver = { planner = \"cruise\", params = { gap_m = 30.0 } }"),
    );
    // The loader does not know the user's planner: it keeps its table for it.
    let scenario = load(&text).unwrap();
    let registry = user_registry();
    scenario.check_planners(&registry).unwrap();
    let own = scenario.vehicles[0].driver.params();
    let parsed = registry
        .parse_params("cruise", &scenario.sim, own)
        .unwrap()
        .unwrap();
    let p = parsed.downcast_ref::<CruiseParams>().unwrap();
    assert_eq!((p.gap_m, p.label.as_str()), (30.0, "scenario"));

    // Out of range in the scenario's table, then in the vehicle's.
    let bad = text.replace("gap_m = 12.0", "gap_m = 120.0");
    let e = load(&bad).unwrap().check_planners(&registry).unwrap_err();
    assert_refused(
        e,
        line_of(&bad, "gap_m = 120.0"),
        "planners.cruise.gap_m",
        &["outside [0, 100]"],
    );
    let bad = text.replace("gap_m = 30.0", "gap_m = -1.0");
    let e = load(&bad).unwrap().check_planners(&registry).unwrap_err();
    assert_refused(
        e,
        line_of(&bad, "gap_m = -1.0"),
        "vehicles[ego].driver.params.gap_m",
        &["outside [0, 100]"],
    );
    // An unknown key.
    let bad = text.replace("label = ", "lable = ");
    let e = load(&bad).unwrap().check_planners(&registry).unwrap_err();
    assert_refused(
        e,
        line_of(&bad, "lable = "),
        "planners.cruise.lable",
        &["lable"],
    );
    // A table for a planner that is not registered.
    let e = scenario
        .check_planners(&BehaviourRegistry::builtin())
        .unwrap_err();
    assert_refused(
        e,
        line_of(&text, "[sim.planners.cruise]"),
        "planners.cruise",
        &["no planner \"cruise\" is registered"],
    );
}

#[test]
fn params_for_a_planner_registered_without_a_type_are_refused_naming_it() {
    let text = text_with(
        "",
        Some("driver = { planner = \"bare\", params = { speed_mps = 3.0 } }"),
    );
    let e = load(&text)
        .unwrap()
        .check_planners(&user_registry())
        .unwrap_err();
    assert_refused(
        e,
        line_of(&text, "speed_mps = 3.0"),
        "vehicles[ego].driver.params.speed_mps",
        &["planner bare takes no parameters"],
    );
    let text = text_with("[sim.planners.bare]\nspeed_mps = 3.0\n", None);
    let e = load(&text)
        .unwrap()
        .check_planners(&user_registry())
        .unwrap_err();
    assert_refused(
        e,
        line_of(&text, "speed_mps = 3.0"),
        "planners.bare.speed_mps",
        &["planner bare takes no parameters"],
    );
}

#[test]
fn an_unknown_planner_in_a_vehicle_s_driver_is_refused_with_its_line() {
    let text = text_with("", Some("driver = { planner = \"pf-isoo\" }"));
    // The loader keeps names it does not know (a user's binary may register them) ...
    let scenario = load(&text).unwrap();
    // ... the run's registry refuses them, at the driver's line.
    let e = scenario
        .check_planners(&BehaviourRegistry::builtin())
        .unwrap_err();
    assert_refused(
        e,
        line_of(&text, "planner = \"pf-isoo\""),
        "vehicles[ego].driver.planner",
        &["unknown planner \"pf-isoo\"", "registered: ", "pf-iso"],
    );
    // A registry that holds the name accepts it.
    let text = text_with("", Some("driver = { planner = \"cruise\" }"));
    load(&text)
        .unwrap()
        .check_planners(&user_registry())
        .unwrap();

    // A prescribed driver's path planner.
    let text = text_with(
        "",
        Some(
            "driver = { prescribed = { path_planner = \"pf-css\", speed_profile = [[0.0, 15.0], [5.0, 12.0]] } }",
        ),
    );
    let e = load(&text)
        .unwrap()
        .check_planners(&BehaviourRegistry::builtin())
        .unwrap_err();
    assert_refused(
        e,
        line_of(&text, "path_planner = \"pf-css\""),
        "vehicles[ego].driver.prescribed.path_planner",
        &["unknown planner \"pf-css\""],
    );
}
