//! The RSS shield from the command line and from a scenario file: `--shield rss`, `[sim] shield`
//! and `[sim.rss]`, the count in the JSON summary, and the errors of bad input.

mod common;

use common::{merge_sim, scratch, stderr};

/// `merge_sim run` with `args` and `--json`, parsed.
fn run_json(dir: &std::path::Path, name: &str, args: &[&str]) -> serde_json::Value {
    common::run_summary(&dir.join(format!("{name}.json")), args)
}

/// The built-in urgent merge's file with `extra` appended.
fn urgent_merge_with(extra: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/builtin/urgent_merge.toml"
    ))
    .unwrap();
    format!("{text}\n{extra}")
}

#[test]
fn the_shield_is_chosen_on_the_command_line_or_in_the_file_and_counted() {
    let dir = scratch("shield_cli");
    // The urgent merge, both cars planned by PF-ISO: the count is the number of events.
    let file = dir.join("urgent_merge.toml");
    std::fs::write(&file, urgent_merge_with("")).unwrap();
    let path = file.to_str().unwrap();
    let off = run_json(&dir, "off", &["--scenario", path]);
    assert_eq!(off["shield_interventions"], 0, "{off}");
    let on = run_json(&dir, "on", &["--scenario", path, "--shield", "rss"]);
    let count = on["shield_interventions"].as_u64().unwrap();
    let events: Vec<&str> = on["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e.as_str())
        .filter(|e| e.contains("the shield of"))
        .collect();
    assert_eq!(count as usize, events.len(), "{events:?}");
    // The same shield from the file.
    let in_file = dir.join("in_file.toml");
    std::fs::write(
        &in_file,
        urgent_merge_with("").replace("[sim]\n", "[sim]\nshield = \"rss\"\n"),
    )
    .unwrap();
    let from_file = run_json(
        &dir,
        "from_file",
        &["--scenario", in_file.to_str().unwrap()],
    );
    assert_eq!(
        from_file["shield_interventions"],
        on["shield_interventions"]
    );
    assert_eq!(from_file["min_gap_m"], on["min_gap_m"]);
}

#[test]
fn a_bad_shield_is_refused_before_any_work() {
    let dir = scratch("shield_cli_bad");
    let json = dir.join("out.json");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--shield",
        "rsss",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("valid: none, rss"), "{err}");
    assert!(!json.exists());

    for (name, extra, words) in [
        ("kind", "", "shield"),
        (
            "param",
            "[sim.rss]\nbrake_min_mps2 = 0.0\n",
            "rss.brake_min_mps2",
        ),
        (
            "unknown",
            "[sim.rss]\nreaction_time_s = 1.0\n",
            "reaction_time_s",
        ),
    ] {
        let text = if name == "kind" {
            urgent_merge_with("").replace("[sim]\n", "[sim]\nshield = \"rsss\"\n")
        } else {
            urgent_merge_with(extra)
        };
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(&file, &text).unwrap();
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--scenario",
            file.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(&format!("{name}.toml")), "{name}: {err}");
        assert!(err.contains(words), "{name}: {err}");
        assert!(err.contains("line "), "{name}: {err}");
        assert!(!json.exists(), "{name}");
    }
}
