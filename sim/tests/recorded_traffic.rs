//! Recorded traffic in the world: interpolation of the recorded states, presence in the
//! planners' observations during the recorded span only, collisions caused by the replay
//! counted apart, the reactive mode's IDM handover, and determinism.

mod common;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use mergesim_types::{Behaviour, BehaviourError, Decision, Lane, Observation, VehicleId};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::idm::{IdmParams, desired_gap_m};
use sim::recorded_traffic::{RecordedState, RecordedTraffic, RecordedVehicle, TrafficMode};
use sim::recording::Recorder;
use sim::registry::{BehaviourRegistry, FactoryInput};
use sim::{RunOptions, RunOutcome, World};

/// Upper lane centre of the default merge road (m).
const UPPER_Y_M: f64 = 5.25;

fn state(time_s: f64, x_m: f64, speed_mps: f64) -> RecordedState {
    RecordedState {
        time_s,
        position_m: [x_m, UPPER_Y_M],
        heading_rad: 0.0,
        speed_mps,
    }
}

fn recorded(name: &str, states: Vec<RecordedState>) -> RecordedVehicle {
    RecordedVehicle {
        name: name.into(),
        length_m: 4.5,
        width_m: 1.8,
        states,
    }
}

use common::spec;

fn config(duration_s: f64, mode: TrafficMode, vehicles: Vec<RecordedVehicle>) -> SimConfig {
    SimConfig {
        duration_s,
        recorded_traffic: RecordedTraffic { mode, vehicles },
        ..SimConfig::default()
    }
}

fn run(config: SimConfig, specs: &[VehicleSpec]) -> RunOutcome {
    World::new(config, specs, &RunOptions::default(), Recorder::disabled())
        .unwrap_or_else(|e| panic!("{e}"))
        .run(|_| {})
        .unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

#[test]
fn recorded_states_are_interpolated_linearly_with_the_heading_on_the_shorter_arc() {
    let v = recorded(
        "r",
        vec![
            RecordedState {
                time_s: 1.0,
                position_m: [10.0, 2.0],
                heading_rad: 3.0,
                speed_mps: 10.0,
            },
            RecordedState {
                time_s: 2.0,
                position_m: [20.0, 4.0],
                heading_rad: -3.0,
                speed_mps: 12.0,
            },
            RecordedState {
                time_s: 4.0,
                position_m: [40.0, 4.0],
                heading_rad: -2.0,
                speed_mps: 8.0,
            },
        ],
    );
    // At the samples: the samples.
    for s in &v.states {
        assert_eq!(v.state_at(s.time_s), Some(*s));
    }
    // Between: linear position and speed.
    let q = v
        .state_at(1.25)
        .unwrap_or_else(|| panic!("inside the span"));
    assert!(
        close(q.position_m[0], 12.5) && close(q.position_m[1], 2.5),
        "{q:?}"
    );
    assert!(close(q.speed_mps, 10.5), "{q:?}");
    // 3.0 → −3.0 turns by 2π − 6 ≈ 0.283 rad through ±π, not by −6 rad: a quarter of the way
    // the heading is 3.0 + 0.0708 (wrapped into [−π, π)).
    let expected = 3.0 + 0.25 * (2.0 * std::f64::consts::PI - 6.0);
    assert!(close(q.heading_rad, expected), "{q:?}");
    let mid = v.state_at(1.5).unwrap_or_else(|| panic!("inside"));
    assert!(
        close(mid.heading_rad.abs(), std::f64::consts::PI),
        "{mid:?}"
    );
    let late = v.state_at(3.0).unwrap_or_else(|| panic!("inside"));
    assert!(
        close(late.heading_rad, -2.5) && close(late.speed_mps, 10.0),
        "{late:?}"
    );
    assert!(close(late.position_m[0], 30.0), "{late:?}");
    // Outside the span: absent.
    assert_eq!(v.state_at(0.999), None);
    assert_eq!(v.state_at(4.001), None);
    // A single state: present the whole run, standing still.
    let parked = recorded("p", vec![state(3.0, 50.0, 4.0)]);
    for t_s in [0.0, 3.0, 100.0] {
        let s = parked
            .state_at(t_s)
            .unwrap_or_else(|| panic!("always present"));
        assert_eq!((s.position_m, s.speed_mps), ([50.0, UPPER_Y_M], 0.0));
    }
}

#[test]
fn bad_recorded_data_is_refused_naming_the_vehicle_and_field() {
    let backwards = recorded("cr-7", vec![state(1.0, 0.0, 1.0), state(1.0, 1.0, 1.0)]);
    let clash = recorded("ego", vec![state(0.0, 0.0, 1.0)]);
    for (v, field) in [
        (
            backwards,
            "recorded_traffic.vehicles[cr-7].states[1].time_s",
        ),
        (clash, "recorded_traffic.vehicles[ego].name"),
    ] {
        let err = World::new(
            config(1.0, TrafficMode::Replay, vec![v]),
            &[spec("ego", 100.0, 10.0, Driver::LaneKeeping)],
            &RunOptions::default(),
            Recorder::disabled(),
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(err.contains(field), "{err}");
    }
}

/// Notes the time of every planning cycle at which it was given each neighbour.
struct Witness {
    seen: Arc<Mutex<BTreeMap<VehicleId, Vec<f64>>>>,
}

impl Behaviour for Witness {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let mut seen = self.seen.lock().map_err(|e| e.to_string())?;
        for n in obs.neighbours {
            seen.entry(n.id).or_default().push(obs.time_s);
            if n.id == 1 {
                // The recorded shape and state.
                if n.shape.length_m != 4.5 || n.shape.width_m != 1.8 || n.state.speed_mps != 12.0 {
                    return Err(format!("recorded neighbour seen as {n:?}").into());
                }
            }
        }
        assert!(obs.shared_paths.is_empty());
        let mut keep = sim::drivers::LaneKeeping {
            lane: mergesim_types::lanes::THROUGH_LANE_ID,
            d_offset_m: 0.0,
        };
        keep.plan(obs)
    }
}

#[test]
fn a_recorded_vehicle_is_a_planners_neighbour_during_its_span_only() {
    let seen = Arc::new(Mutex::new(BTreeMap::new()));
    let shared = Arc::clone(&seen);
    let mut registry = BehaviourRegistry::new();
    registry
        .register(
            "witness",
            Arc::new(move |_: &FactoryInput<'_>| {
                Ok(Box::new(Witness {
                    seen: Arc::clone(&shared),
                }) as Box<dyn Behaviour>)
            }),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    // 100 m ahead in the other lane, from t = 1 s to t = 2 s.
    let r = RecordedVehicle {
        states: vec![
            RecordedState {
                time_s: 1.0,
                position_m: [200.0, 1.75],
                heading_rad: 0.0,
                speed_mps: 12.0,
            },
            RecordedState {
                time_s: 2.0,
                position_m: [212.0, 1.75],
                heading_rad: 0.0,
                speed_mps: 12.0,
            },
        ],
        ..recorded("cr-1", Vec::new())
    };
    let specs = [spec("ego", 100.0, 10.0, Driver::planner("witness"))];
    World::with_registry(
        config(3.0, TrafficMode::Replay, vec![r]),
        &specs,
        &RunOptions::default(),
        Recorder::disabled(),
        &registry,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .run(|_| {})
    .unwrap_or_else(|e| panic!("{e}"));
    let seen = seen.lock().unwrap_or_else(|e| panic!("{e}"));
    let times = seen.get(&1).cloned().unwrap_or_default();
    // Planning every 0.1 s: seen at 1.0, 1.1, …, 2.0 (within rounding of the step clock).
    assert!(times.len() >= 10, "{times:?}");
    assert!(
        times.iter().all(|t| (1.0 - 1e-9..=2.0 + 1e-9).contains(t)),
        "{times:?}"
    );
}

/// The ego holds the upper lane at 10 m/s from x = 100 m; a recorded car follows it from x = 0
/// at 15 m/s, closing at 5 m/s: its front reaches the ego's rear after about
/// (100 − 4.5) / 5 ≈ 19.1 s.
fn rear_end(mode: TrafficMode) -> (SimConfig, Vec<VehicleSpec>) {
    let follower = recorded(
        "cr-follower",
        vec![state(0.0, 0.0, 15.0), state(19.6, 294.0, 15.0)],
    );
    (
        config(20.0, mode, vec![follower]),
        vec![spec("ego", 100.0, 10.0, Driver::LaneKeeping)],
    )
}

#[test]
fn replay_running_into_a_simulated_car_from_behind_is_counted_apart() {
    let (config, specs) = rear_end(TrafficMode::Replay);
    let outcome = World::new(
        config,
        &specs,
        &RunOptions {
            keep_time_series: true,
            ..RunOptions::default()
        },
        Recorder::disabled(),
    )
    .and_then(|w| w.run(|_| {}))
    .unwrap_or_else(|e| panic!("{e}"));
    // The recorded box is in the physics scene: it shoves the ego forward (the ego holds
    // 10 m/s until then).
    let speed_at = |lo: f64, hi: f64| {
        outcome
            .time_series
            .iter()
            .filter(|r| r.t_s >= lo && r.t_s <= hi)
            .map(|r| r.speed_mps)
            .fold(0.0, f64::max)
    };
    assert!(speed_at(10.0, 18.9) < 10.5, "{}", speed_at(10.0, 18.9));
    assert!(speed_at(19.1, 20.0) > 12.0, "{}", speed_at(19.1, 20.0));
    let safety = &outcome.safety;
    // The first contact, then the recorded car (kinematic: it never yields) keeps pushing:
    // more contact episodes, all the replay's.
    assert!(!safety.collisions.is_empty(), "{:?}", outcome.events);
    assert!(
        safety.collisions.iter().all(|c| c.caused_by_replay),
        "{:?}",
        outcome.events
    );
    assert_eq!(
        safety.collisions_caused_by_replay as usize,
        safety.collisions.len()
    );
    let t_s = safety.collisions[0].t_s;
    assert!((18.8..19.4).contains(&t_s), "{t_s}");
    // Touching: within the contact tolerance.
    let tolerance_m = sim::safety::SafetyParams::default().contact_tolerance_m;
    let gap = safety.min_gap_to_recorded_m.unwrap_or(f64::INFINITY);
    assert!(gap <= tolerance_m, "{gap}");
    assert_eq!(safety.min_ttc_to_recorded_s, Some(0.0));
    // Not the ego's collision: its metrics do not count it.
    assert_eq!(outcome.vehicles.len(), 1);
    assert!(!outcome.vehicles[0].collided);
    assert!(outcome.events.iter().any(
        |e| matches!(e, sim::SimEvent::Collision { event, .. } if event.caused_by_replay)
            && e.to_string().contains("caused by the replay")
    ));
}

#[test]
fn reactive_hands_over_to_idm_when_the_gap_criterion_says_and_does_not_collide() {
    let (config, specs) = rear_end(TrafficMode::Reactive);
    let idm = config.idm.clone();
    assert_eq!(idm, IdmParams::default());
    let outcome = run(config, &specs);
    assert!(outcome.safety.collisions.is_empty(), "{:?}", outcome.events);
    let handovers: Vec<String> = outcome
        .events
        .iter()
        .filter(|e| matches!(e, sim::SimEvent::RecordedHandover { .. }))
        .map(ToString::to_string)
        .collect();
    assert_eq!(handovers.len(), 1, "{:?}", outcome.events);
    // By hand: v = 15 m/s, Δv = 5 m/s, s* = 2 + 15 · 1.6 + 15 · 5 / (2 √(0.73 · 1.67))
    // = 26 + 75 / 2.2083 = 59.96 m. The bumper gap at t is 100 − 4.5 − 5 t (the ego holding
    // 10 m/s), so the recording at t + 0.002 s leaves less than s* from
    // t = (95.5 − 59.96) / 5 − 0.002 ≈ 7.1 s on.
    let safe_gap_m = 2.0 + 15.0 * 1.6 + 15.0 * 5.0 / (2.0 * (0.73f64 * 1.67).sqrt());
    assert!((safe_gap_m - 59.96).abs() < 0.01, "{safe_gap_m}");
    assert!((desired_gap_m(&idm, 15.0, 5.0) - safe_gap_m).abs() < 1e-12);
    let t_expected_s = (95.5 - safe_gap_m) / 5.0 - 0.002;
    let text = &handovers[0];
    assert!(text.contains("hands over to IDM"), "{text}");
    let number_after = |key: &str| -> f64 {
        let rest = &text[text.find(key).unwrap_or_else(|| panic!("{key} in {text}")) + key.len()..];
        let end = rest.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'));
        rest[..end.unwrap_or(rest.len())]
            .parse()
            .unwrap_or_else(|e| panic!("{e}: {text}"))
    };
    let t_s = number_after("t = ");
    let gap_m = number_after("gap of ");
    let s_star_m = number_after("s* = ");
    let v = number_after("(v = ");
    let dv = number_after("Δv = ");
    // The ego's speed varies by a few cm/s around 10 m/s (tracking), its centre of gravity is
    // not its box centre: 0.1 s covers both.
    assert!(
        (t_s - t_expected_s).abs() < 0.1,
        "{t_s} vs {t_expected_s}: {text}"
    );
    assert!(gap_m <= s_star_m, "{text}");
    assert!((v - 15.0).abs() < 1e-9 && (dv - 5.0).abs() < 0.05, "{text}");
    assert!(
        (s_star_m - desired_gap_m(&idm, v, dv)).abs() < 0.02,
        "{text}"
    );
    // IDM kept it behind: a gap of at least the jam gap s₀ in the end.
    let gap = outcome
        .safety
        .min_gap_to_recorded_m
        .unwrap_or_else(|| panic!("followed"));
    assert!(gap > 1.0, "{gap}");
    println!("{text}; min gap to recorded {gap:.3} m");
}

#[test]
fn a_simulated_car_hitting_a_standing_recorded_car_is_its_own_collision() {
    // A parked car (one state) 50 m ahead of the ego in its lane.
    let parked = recorded("cr-parked", vec![state(0.0, 150.0, 0.0)]);
    let outcome = run(
        config(5.5, TrafficMode::Replay, vec![parked]),
        &[spec("ego", 100.0, 10.0, Driver::LaneKeeping)],
    );
    let safety = &outcome.safety;
    // The ego bounces off the immovable box and may touch it again: one or more episodes,
    // none the replay's.
    assert!(!safety.collisions.is_empty(), "{:?}", outcome.events);
    assert!(
        safety.collisions.iter().all(|c| !c.caused_by_replay),
        "{:?}",
        outcome.events
    );
    assert_eq!(safety.collisions_caused_by_replay, 0);
    // (50 − 4.5) / 10 ≈ 4.55 s.
    assert!(
        (4.3..4.8).contains(&safety.collisions[0].t_s),
        "{:?}",
        safety.collisions
    );
    assert!(outcome.vehicles[0].collided);
}

#[test]
fn recorded_pairs_are_not_checked_and_recorded_traffic_does_not_count_in_mode_none() {
    // Two recorded cars overlapping each other for the whole run: no collision.
    let a = recorded("cr-a", vec![state(0.0, 300.0, 0.0)]);
    let b = recorded("cr-b", vec![state(0.0, 302.0, 0.0)]);
    let specs = [spec("ego", 0.0, 10.0, Driver::LaneKeeping)];
    let outcome = run(
        config(1.0, TrafficMode::Replay, vec![a.clone(), b.clone()]),
        &specs,
    );
    assert!(outcome.safety.collisions.is_empty(), "{:?}", outcome.events);
    assert!(outcome.safety.pairs.iter().all(|p| p.id_a == 0));
    // Mode none: nothing spawned.
    let parked = recorded("cr-parked", vec![state(0.0, 20.0, 0.0)]);
    let outcome = run(config(3.0, TrafficMode::None, vec![parked]), &specs);
    assert!(outcome.safety.collisions.is_empty());
    assert_eq!(outcome.safety.min_gap_to_recorded_m, None);
}

fn run_on(threads: usize) -> RunOutcome {
    let vehicles = vec![
        recorded(
            "cr-1",
            vec![state(0.0, 0.0, 15.0), state(10.0, 150.0, 15.0)],
        ),
        RecordedVehicle {
            states: vec![
                RecordedState {
                    time_s: 0.5,
                    position_m: [60.0, 1.75],
                    heading_rad: 0.0,
                    speed_mps: 12.0,
                },
                RecordedState {
                    time_s: 8.0,
                    position_m: [150.0, 1.75],
                    heading_rad: 0.0,
                    speed_mps: 12.0,
                },
            ],
            ..recorded("cr-2", Vec::new())
        },
    ];
    let specs = [
        spec("ego", 40.0, 12.0, Driver::planner("pf-iso")),
        VehicleSpec {
            lane: Lane::Lower.into(),
            ..spec("other", 20.0, 12.0, Driver::Idm)
        },
    ];
    let mut world = World::new(
        config(6.0, TrafficMode::Reactive, vehicles),
        &specs,
        &RunOptions::default(),
        Recorder::disabled(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    world.plan_on(Arc::new(pool));
    world.run(|_| {}).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn recorded_traffic_runs_are_bitwise_identical_on_1_and_4_threads() {
    let one = run_on(1);
    let four = run_on(4);
    let bits = |o: &RunOutcome| {
        serde_json::to_string(&(&o.safety, &o.vehicles, &o.events)).unwrap_or_default()
    };
    assert!(one.safety.min_gap_to_recorded_m.is_some());
    assert_eq!(bits(&one), bits(&four));
}

#[test]
fn the_recording_draws_recorded_vehicles_with_their_names() {
    use re_log_encoding::DecoderApp;
    use rerun::log::{Chunk, LogMsg};
    let dir = std::env::temp_dir().join(format!("mergesim_recorded_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let path = dir.join("run.rrd");
    let parked = recorded("cr-parked", vec![state(0.0, 150.0, 0.0)]);
    let recorder = Recorder::new_file(&path, "mergesim_test").unwrap_or_else(|e| panic!("{e}"));
    World::new(
        config(0.5, TrafficMode::Replay, vec![parked]),
        &[spec("ego", 100.0, 10.0, Driver::LaneKeeping)],
        &RunOptions::default(),
        recorder,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .run(|_| {})
    .unwrap_or_else(|e| panic!("{e}"));
    let file = std::fs::File::open(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut labels = Vec::new();
    let component = rerun::Boxes2D::descriptor_labels().component;
    for msg in DecoderApp::decode_lazy(std::io::BufReader::new(file)) {
        let msg = msg.unwrap_or_else(|e| panic!("{e}"));
        if let LogMsg::ArrowMsg(_, arrow_msg) = &msg {
            let chunk = Chunk::from_arrow_msg(arrow_msg).unwrap_or_else(|e| panic!("{e}"));
            if chunk.entity_path().to_string() == "/world/recorded_vehicles" {
                for row in chunk.iter_component::<rerun::components::Text>(component) {
                    labels.extend(row.iter().map(|t| t.to_string()));
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    // One label per logged instant (20 Hz over 0.5 s, the first instant after the first log
    // period).
    assert!(labels.len() >= 10, "{labels:?}");
    assert!(labels.iter().all(|l| l == "cr-parked"), "{labels:?}");
}

#[test]
fn recorded_traffic_works_on_a_turned_lane_road_far_from_the_origin() {
    use mergesim_types::lanes::{LaneId, LaneSpec};
    // One lane 5.9 km from the origin (Rapier works around a local origin near the road),
    // heading 0.5 rad.
    let heading_rad: f64 = 0.5;
    let (s, c) = heading_rad.sin_cos();
    let origin = [5900.0, 3000.0];
    let at = |s_m: f64| [origin[0] + s_m * c, origin[1] + s_m * s];
    let lane = LaneSpec::new(
        LaneId(1),
        (0..=8).map(|k| at(50.0 * k as f64)).collect(),
        3.5,
    );
    let ego = VehicleSpec {
        lane: LaneId(1).into(),
        x_m: 50.0,
        ..spec("ego", 0.0, 10.0, Driver::LaneKeeping)
    };
    // Parked 50 m ahead along the lane: the ego hits it (its own collision) after about
    // (50 − 4.5) / 10 ≈ 4.55 s, as on the straight road at the origin.
    let parked = RecordedVehicle {
        states: vec![RecordedState {
            time_s: 0.0,
            position_m: at(100.0),
            heading_rad,
            speed_mps: 0.0,
        }],
        ..recorded("cr-parked", Vec::new())
    };
    let config = SimConfig {
        duration_s: 5.0,
        lane_road: Some(sim::road_config::LaneRoadConfig {
            lanes: vec![lane],
            ..sim::road_config::LaneRoadConfig::default()
        }),
        recorded_traffic: RecordedTraffic {
            mode: TrafficMode::Replay,
            vehicles: vec![parked],
        },
        ..SimConfig::default()
    };
    let outcome = World::new(
        config,
        &[ego],
        &RunOptions {
            keep_time_series: true,
            ..RunOptions::default()
        },
        Recorder::disabled(),
    )
    .and_then(|w| w.run(|_| {}))
    .unwrap_or_else(|e| panic!("{e}"));
    // Rapier stops the ego at the box (at the right place, despite the local origin): its
    // centre never gets within half of both lengths (4.5 m) of the parked car's.
    let furthest_m = outcome
        .time_series
        .iter()
        .map(|r| (r.x_m - origin[0]) * c + (r.y_m - origin[1]) * s)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((94.0..96.0).contains(&furthest_m), "{furthest_m}");
    let safety = &outcome.safety;
    assert!(!safety.collisions.is_empty(), "{:?}", outcome.events);
    assert!(safety.collisions.iter().all(|c| !c.caused_by_replay));
    assert!(
        (4.3..4.8).contains(&safety.collisions[0].t_s),
        "{:?}",
        safety.collisions
    );
    assert!(outcome.vehicles[0].collided);
}
