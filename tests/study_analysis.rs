//! The statistics of a study from given rows (no simulation): pairing by instance, the window
//! a motion-state endpoint is tested on, exclusions, the Holm family, the collision table.

use std::collections::BTreeMap;
use std::path::Path;

use mergesim::inference;
use mergesim::study::analyse;
use mergesim::study::plan::StudyPlan;
use mergesim::study::runner::{EndpointValues, StudyRow};
use mergesim::sweep::{RunStatus, instance_seed};

const PLAN: &str = r#"name = "synthetic"
scenario = "urgent_merge"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"

[instances]
n = 6
seed = 1

[endpoints]
primary = { figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }
secondary = [
  { figure = "obstacle.max_abs_sideslip_rad", threshold = "0.002 rad" },
  { figure = "ego.min_speed_mps", threshold = "0.5 m/s" },
]
"#;

fn plan() -> StudyPlan {
    StudyPlan::from_text(PLAN, Path::new("synthetic.toml")).unwrap()
}

/// A completed row whose endpoints take `pre` before the contact and `whole` over the run.
fn row(instance: u64, planner: &str, collided: bool, pre: [f64; 3], whole: [f64; 3]) -> StudyRow {
    let names = [
        "obstacle.max_abs_yaw_rate_radps",
        "obstacle.max_abs_sideslip_rad",
        "ego.min_speed_mps",
    ];
    let endpoints: BTreeMap<String, EndpointValues> = names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            (
                n.to_string(),
                EndpointValues {
                    pre_contact: Some(pre[k]),
                    whole_run: Some(whole[k]),
                },
            )
        })
        .collect();
    StudyRow {
        cell: 0,
        instance,
        planner: planner.into(),
        seed: instance_seed(1, instance),
        status: RunStatus::Completed,
        error: None,
        collided,
        collisions: u64::from(collided),
        first_contact_t_s: collided.then_some(5.0),
        endpoints,
    }
}

#[test]
fn paired_statistics_windows_holm_and_collisions() {
    let plan = plan();
    // Reference (pf-sp) and planner (pf-iso) on six instances; pf-iso's pre-contact yaw-rate
    // peak is 0.001·(i+1) higher; instance 2 of pf-iso collided, with a post-contact peak of
    // 1 rad/s; instances 4 and 5 of the reference collided too.
    let mut rows = Vec::new();
    for i in 0..6u64 {
        let x = i as f64;
        let reference_collided = i >= 4;
        rows.push(row(
            i,
            "pf-sp",
            reference_collided,
            [0.01 + 0.002 * x, 0.001, 14.0 + 0.1 * x],
            [0.01 + 0.002 * x, 0.001, 14.0 + 0.1 * x],
        ));
        let collided = i == 2 || i == 4;
        let pre = [0.01 + 0.002 * x + 0.001 * (x + 1.0), 0.0011, 14.0 + 0.1 * x];
        let mut whole = pre;
        if i == 2 {
            whole[0] = 1.0;
        }
        rows.push(row(i, "pf-iso", collided, pre, whole));
    }
    // Rows in any order give the same tables.
    let mut shuffled = rows.clone();
    shuffled.reverse();
    let a = analyse(&plan, &rows);
    assert_eq!(a, analyse(&plan, &shuffled));

    let find = |endpoint: &str, window: &str| {
        a.endpoints
            .iter()
            .find(|e| e.endpoint == endpoint && e.window == window)
            .unwrap()
    };
    // The tested primary: pre-contact differences 0.001·(i+1).
    let primary = find("obstacle.max_abs_yaw_rate_radps", "pre-contact");
    assert!(primary.tested && primary.role == "primary");
    assert_eq!((primary.n, primary.n_excluded), (6, 0));
    let d: Vec<f64> = (0..6)
        .map(|i| {
            let x = i as f64;
            (0.01 + 0.002 * x + 0.001 * (x + 1.0)) - (0.01 + 0.002 * x)
        })
        .collect();
    let t = inference::paired_t(&d, 0.95).unwrap();
    assert_eq!(primary.mean_difference, Some(d.iter().sum::<f64>() / 6.0));
    assert_eq!(primary.ci95, Some(t.ci));
    assert_eq!(primary.p_t, Some(t.p_two_sided));
    assert_eq!(
        primary.p_wilcoxon,
        Some(inference::wilcoxon_signed_rank(&d).unwrap().p_two_sided)
    );
    assert_eq!(primary.p_t_holm, None, "the primary endpoint stands alone");
    // Nearest rank over the six sorted differences: median = 3rd, p90 = 6th.
    let mut sorted = d.clone();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(primary.median_difference, Some(sorted[2]));
    assert_eq!(primary.p90_difference, Some(sorted[5]));
    // CI inside (−0.01, 0.01): negligible.
    assert_eq!(primary.verdict.name(), "negligible");
    // The whole-run figure (the post-contact peak of instance 2) is beside it, untested.
    let whole = find("obstacle.max_abs_yaw_rate_radps", "whole-run");
    assert!(!whole.tested);
    assert!(whole.mean_difference.unwrap() > 0.1);
    assert_eq!(whole.verdict.name(), "inconclusive");

    // Holm over the two tested secondary endpoints (this pair, this cell) only.
    let sideslip = find("obstacle.max_abs_sideslip_rad", "pre-contact");
    let speed = find("ego.min_speed_mps", "pre-contact");
    let raw = [sideslip.p_t.unwrap(), speed.p_t.unwrap()];
    let adjusted = inference::holm(&raw);
    assert_eq!(sideslip.p_t_holm, Some(adjusted[0]));
    assert_eq!(speed.p_t_holm, Some(adjusted[1]));
    assert_eq!(find("ego.min_speed_mps", "whole-run").p_t_holm, None);
    // Identical speeds: every difference 0, a point interval at 0 → negligible.
    assert_eq!(speed.ci95, Some([0.0, 0.0]));
    assert_eq!(speed.verdict.name(), "negligible");

    // Collisions: both (4), only planner (2), only reference (5), neither (0, 1, 3).
    let c = &a.collisions[0];
    assert_eq!(
        (c.n, c.both, c.only_planner, c.only_reference, c.neither),
        (6, 1, 1, 1, 3)
    );
    let table = inference::Discordance {
        both: 1,
        only_first: 1,
        only_second: 1,
        neither: 3,
    };
    assert_eq!(c.p_mcnemar, inference::mcnemar_exact(&table));
    let newcombe = inference::newcombe_paired_difference(&table, 0.95).unwrap();
    assert_eq!(c.ci95, Some(newcombe.ci));
    assert_eq!(c.difference, Some(0.0));
}

#[test]
fn failed_runs_and_null_figures_leave_their_pairs_out() {
    let plan = plan();
    let mut rows = Vec::new();
    for i in 0..6u64 {
        let x = i as f64;
        rows.push(row(
            i,
            "pf-sp",
            false,
            [0.01, 0.001, 14.0],
            [0.01, 0.001, 14.0],
        ));
        rows.push(row(
            i,
            "pf-iso",
            false,
            [0.01 + 0.001 * x, 0.001, 14.0],
            [0.01, 0.001, 14.0],
        ));
    }
    // Instance 1 of pf-iso diverged; instance 3's reference sideslip is null (never measured).
    let failed = rows
        .iter_mut()
        .find(|r| r.instance == 1 && r.planner == "pf-iso")
        .unwrap();
    failed.status = RunStatus::Diverged;
    failed.error = Some("diverged".into());
    failed.endpoints.clear();
    let null = rows
        .iter_mut()
        .find(|r| r.instance == 3 && r.planner == "pf-sp")
        .unwrap();
    null.endpoints
        .get_mut("obstacle.max_abs_sideslip_rad")
        .unwrap()
        .pre_contact = None;
    let a = analyse(&plan, &rows);
    let get = |endpoint: &str| {
        a.endpoints
            .iter()
            .find(|e| e.endpoint == endpoint && e.tested)
            .unwrap()
    };
    assert_eq!(
        (
            get("obstacle.max_abs_yaw_rate_radps").n,
            get("obstacle.max_abs_yaw_rate_radps").n_excluded
        ),
        (5, 1)
    );
    assert_eq!(
        (
            get("obstacle.max_abs_sideslip_rad").n,
            get("obstacle.max_abs_sideslip_rad").n_excluded
        ),
        (4, 2)
    );
    assert_eq!(a.collisions[0].n, 5);
    assert_eq!(a.failed_runs.len(), 1);
}
