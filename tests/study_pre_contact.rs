//! The per-vehicle figures frozen at a run's first contact (`pre_contact`): on a run with a
//! collision they are never beyond the whole-run figures, and they equal the whole-run
//! figures of the same run stopped at the last logged instant before the contact.

use mergesim::experiment::{InstanceOptions, run_quietly};
use mergesim::scenarios::scenario::Scenario;

fn rear_end() -> Scenario {
    Scenario::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/rear_end.toml"
    ))
    .unwrap()
}

#[test]
fn pre_contact_figures_are_the_run_truncated_at_its_first_contact() {
    let scenario = rear_end();
    let finished = run_quietly(&scenario, &InstanceOptions::default()).unwrap();
    let outcome = &finished.outcome;
    let contact_s = outcome.safety.collisions[0].t_s;
    // The rear car keeps pushing after the impact: the whole-run figures move after it.
    let mut moved = false;
    for v in &outcome.vehicles {
        let before = v
            .pre_contact
            .as_deref()
            .expect("a run with a contact freezes figures");
        assert!(before.pre_contact.is_none());
        assert!(before.max_abs_yaw_rate_radps <= v.max_abs_yaw_rate_radps);
        assert!(before.max_abs_sideslip_rad <= v.max_abs_sideslip_rad);
        assert!(before.peak_abs_accel_long_mps2 <= v.peak_abs_accel_long_mps2);
        assert!(before.min_speed_mps >= v.min_speed_mps);
        assert!(before.max_speed_mps <= v.max_speed_mps);
        assert!(before.samples < v.samples);
        moved |= before.peak_abs_accel_long_mps2 < v.peak_abs_accel_long_mps2;
        // Through the summary's accessor too.
        assert_eq!(v.before_first_contact(), before);
    }
    assert!(
        moved,
        "the impact should raise some vehicle's peak acceleration"
    );

    // The same run stopped at the last logged instant strictly before the contact.
    let log_period_s = scenario.sim.log_period_s;
    let steps = (contact_s / log_period_s - 1e-9).floor();
    let mut truncated = scenario.clone();
    truncated.sim.duration_s = steps * log_period_s;
    let short = run_quietly(&truncated, &InstanceOptions::default()).unwrap();
    assert!(short.outcome.safety.collisions.is_empty());
    for (v, s) in outcome.vehicles.iter().zip(&short.outcome.vehicles) {
        let mut before = (**v.pre_contact.as_ref().unwrap()).clone();
        let mut whole_short = s.clone();
        // Bitwise the same figures (not just close): the same samples fed the same way.
        before.collided = false;
        whole_short.collided = false;
        assert_eq!(before, whole_short, "vehicle {}", v.id);
    }
}

#[test]
fn a_run_without_contact_keeps_no_pre_contact_copy() {
    let scenario = Scenario::load("urgent_merge").unwrap();
    let mut short = scenario.clone();
    short.sim.duration_s = 2.0;
    let finished = run_quietly(&short, &InstanceOptions::default()).unwrap();
    assert_eq!(finished.summary.collisions, 0);
    for v in &finished.summary.vehicles {
        assert!(v.pre_contact.is_none());
        assert_eq!(v.before_first_contact(), v);
    }
    // And the run JSON has no `pre_contact` key then (unchanged for runs without contact).
    let json = serde_json::to_value(&finished.summary).unwrap();
    assert!(json["vehicles"][0].get("pre_contact").is_none());
}
