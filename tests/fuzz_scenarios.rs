//! Property test: mutated scenario files never panic or hang the loader or a short simulation.
//!
//! Each case takes a built-in scenario's TOML and damages it the way hostile or careless users
//! do — a number replaced by NaN, ±∞, a huge, tiny, negative or merely unusual one, or by a
//! string, a boolean, an array or a range; a line deleted or duplicated; a known key added to another table; the text cut
//! short — then loads it. Half the cases start from the scenario with every field of every
//! table written out, so the damage reaches every section. A scenario that loads is simulated for at most half a second. Errors
//! are fine (they are the point); a panic or a run that does not return within the watchdog's
//! time fails the property.

use std::sync::mpsc;
use std::time::Duration;

use mergesim::experiment::{InstanceOptions, run_quietly};
use mergesim::scenarios::builtin;
use mergesim::scenarios::scenario::Scenario;
use proptest::prelude::*;

/// Numbers a damaged field may take.
const NUMBERS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "0",
    "0.0",
    "-1",
    "-1.0",
    "1e300",
    "-1e300",
    "1e-300",
    "1e-9",
    "0.5",
    "2.0",
    "7.0",
    "100.0",
    "5000.0",
    "9223372036854775807",
];

/// Other things a damaged field may hold.
const OTHER: &[&str] = &[
    "18446744073709551616",
    "\"text\"",
    "true",
    "[1.0, 2.0, 3.0]",
    "{ uniform = [1e300, -1e300] }",
    "{ normal = { std = nan, clip = [-1.0, 1.0] } }",
];

/// Keys that exist somewhere in a scenario, to be dropped into the wrong table.
const KEYS: &[&str] = &[
    "mu",
    "dt_s",
    "duration_s",
    "lane_width_m",
    "end_x_m",
    "step_time_s",
    "waypoint_count",
    "lookahead_min_m",
    "latency_s",
    "drop_probability",
    "x_m",
    "speed_mps",
    "max_scp_iterations",
];

#[derive(Clone, Debug)]
enum Damage {
    /// Replace the value of the n-th `key = value` line.
    Value(usize, &'static str),
    /// Delete the n-th line.
    Delete(usize),
    /// Duplicate the n-th line.
    Duplicate(usize),
    /// Insert `key = value` after the n-th line.
    Insert(usize, &'static str, &'static str),
    /// Cut the text at this fraction of its length (on a character boundary).
    Truncate(f64),
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        12 => (any::<usize>(), proptest::sample::select(NUMBERS)).prop_map(|(n, v)| Damage::Value(n, v)),
        2 => (any::<usize>(), proptest::sample::select(OTHER)).prop_map(|(n, v)| Damage::Value(n, v)),
        1 => any::<usize>().prop_map(Damage::Delete),
        1 => any::<usize>().prop_map(Damage::Duplicate),
        1 => (any::<usize>(), proptest::sample::select(KEYS), proptest::sample::select(NUMBERS))
            .prop_map(|(n, k, v)| Damage::Insert(n, k, v)),
        1 => (0.0..1.0f64).prop_map(Damage::Truncate),
    ]
}

fn apply(text: &str, damages: &[Damage]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for d in damages {
        if lines.is_empty() {
            break;
        }
        match d {
            Damage::Value(n, value) => {
                // Lines assigning a number (the values the simulator computes with).
                let assignments: Vec<usize> = (0..lines.len())
                    .filter(|&i| {
                        let line = lines[i].trim_start();
                        !line.starts_with('#')
                            && line
                                .split_once(" = ")
                                .is_some_and(|(_, v)| v.trim().parse::<f64>().is_ok())
                    })
                    .collect();
                if let Some(&i) = assignments.get(n % assignments.len().max(1)) {
                    let key = lines[i].split(" = ").next().unwrap_or("").to_string();
                    lines[i] = format!("{key} = {value}");
                }
            }
            Damage::Delete(n) => {
                let i = n % lines.len();
                lines.remove(i);
            }
            Damage::Duplicate(n) => {
                let i = n % lines.len();
                let line = lines[i].clone();
                lines.insert(i, line);
            }
            Damage::Insert(n, key, value) => {
                let i = n % lines.len();
                lines.insert(i + 1, format!("{key} = {value}"));
            }
            Damage::Truncate(fraction) => {
                let joined = lines.join("\n");
                let mut cut = (joined.len() as f64 * fraction) as usize;
                while !joined.is_char_boundary(cut) {
                    cut -= 1;
                }
                lines = joined[..cut].lines().map(str::to_string).collect();
            }
        }
    }
    lines.join("\n") + "\n"
}

/// Loads `text` and, if it loads, simulates at most 0.5 s of it: `Ok(description)` unless
/// something panicked.
fn load_and_run(text: String) -> String {
    match Scenario::from_toml(&text, "fuzz.toml") {
        Err(e) => {
            let message = e.to_string();
            assert!(!message.is_empty());
            format!("refused: {message}")
        }
        Ok(mut scenario) => {
            scenario.sim.duration_s = scenario.sim.duration_s.min(0.5);
            let options = InstanceOptions {
                seed: Some(7),
                ..InstanceOptions::default()
            };
            match run_quietly(&scenario, &options) {
                Ok(finished) => format!("ran: {} collisions", finished.summary.collisions),
                Err(e) => format!("run failed: {e}"),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenarios_never_panic_or_hang(
        which in 0..builtin::names().len(),
        full in any::<bool>(),
        damages in proptest::collection::vec(damage(), 1..3),
    ) {
        let name = builtin::names()[which];
        // The file as shipped, or every field of every table written out (so that damage can
        // reach `[sim.tracker]`, `[sim.safety]`, every planner field, ...).
        let base = if full {
            toml::to_string(&Scenario::load(name).unwrap()).unwrap()
        } else {
            builtin::toml_of(name).unwrap().to_string()
        };
        let text = apply(&base, &damages);
        let (send, receive) = mpsc::channel();
        let worker_text = text.clone();
        let worker = std::thread::Builder::new()
            .stack_size(16 << 20)
            .spawn(move || {
                let outcome = std::panic::catch_unwind(|| load_and_run(worker_text));
                let _ = send.send(outcome);
            })
            .unwrap();
        match receive.recv_timeout(Duration::from_secs(60)) {
            Ok(Ok(_)) => {}
            Ok(Err(_)) => {
                return Err(TestCaseError::fail(format!("panicked on {name} with {damages:?}")));
            }
            Err(_) => {
                return Err(TestCaseError::fail(format!(
                    "no answer within 60 s on {name} with {damages:?}"
                )));
            }
        }
        let _ = worker.join();
    }
}
