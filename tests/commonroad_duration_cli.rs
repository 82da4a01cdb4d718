//! A run of a CommonRoad file longer than its recording warns that the recorded vehicles leave
//! when their recordings end; a run within it does not.

use std::process::Command;

fn run(duration: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_merge_sim"))
        .args([
            "run",
            "--scenario",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/data/commonroad/USA_US101-4_1_T-1.xml"
            ),
            "--planner",
            "pf-cs",
            "--no-rrd",
            "--quiet",
            "--duration",
            duration,
        ])
        .output()
        .expect("merge_sim runs")
}

#[test]
fn a_run_past_the_recording_warns() {
    let past = run("12");
    assert!(
        past.status.success(),
        "{}",
        String::from_utf8_lossy(&past.stderr)
    );
    let err = String::from_utf8_lossy(&past.stderr);
    assert!(
        err.contains("warning: the run lasts 12.00 s, past the recording's end"),
        "{err}"
    );
    let within = run("5");
    assert!(within.status.success());
    assert!(
        !String::from_utf8_lossy(&within.stderr).contains("past the recording"),
        "{}",
        String::from_utf8_lossy(&within.stderr)
    );
}
