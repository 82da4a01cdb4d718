//! Every lane change is an event, in either direction: a scripted vehicle driven from the upper
//! lane down into the lower one and back up, on the straight merge road and on the same road
//! bent on a 300 m-radius curve (lane membership in the lane frame).

mod common;

use std::sync::Arc;

use mergesim_types::lanes::{LaneId, LaneRoad};
use mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};
use sim::config::{Driver, SimConfig};
use sim::registry::{BehaviourRegistry, FactoryInput};
use sim::road_config::{CurvedMergeConfig, LaneRoadConfig};

/// Follows the upper lane's centre, weaves to the lower lane's centre between s = 40 and 60 m
/// (of the upper lane), holds it to 110 m and weaves back by 130 m: the path is the upper lane's
/// centreline offset by d(s) (0 → −3.5 m → 0), so it works on any merge road, straight or bent.
struct Weave {
    lanes: Arc<LaneRoad>,
}

fn offset_m(s_m: f64) -> f64 {
    let smooth = |u: f64| {
        let u = u.clamp(0.0, 1.0);
        u * u * (3.0 - 2.0 * u)
    };
    -3.5 * (smooth((s_m - 40.0) / 20.0) - smooth((s_m - 110.0) / 20.0))
}

impl Behaviour for Weave {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let upper = self.lanes.lane(LaneId(1)).ok_or("no lane 1")?;
        let s0 = upper.project([obs.ego.x_m, obs.ego.y_m]).s_m;
        let v = obs.target_speed_mps;
        let path = (0..=20)
            .map(|i| {
                let s = s0 + 2.5 * i as f64;
                let [x_m, y_m] = upper.point(s, offset_m(s));
                PathPoint {
                    x_m,
                    y_m,
                    speed_mps: v,
                    t_s: obs.time_s + 2.5 * i as f64 / v,
                }
            })
            .collect();
        Ok(Decision::follow(path))
    }
}

fn events_of(config: SimConfig, x_m: f64) -> (Vec<String>, u32) {
    let lanes = Arc::new(config.lanes().unwrap());
    let mut registry = BehaviourRegistry::builtin();
    registry
        .register(
            "weave",
            Arc::new(move |_: &FactoryInput<'_>| {
                Ok(Box::new(Weave {
                    lanes: Arc::clone(&lanes),
                }) as Box<dyn Behaviour>)
            }),
        )
        .unwrap();
    let specs = [common::spec("weaver", x_m, 12.0, Driver::planner("weave"))];
    let config = SimConfig {
        duration_s: 16.0,
        ..config
    };
    let outcome = common::run_with(config, &specs, &registry);
    let crossings = outcome.vehicles[0]
        .paper_metrics
        .as_ref()
        .map_or(0, |p| p.divider_crossings);
    (
        outcome.events.iter().map(ToString::to_string).collect(),
        crossings,
    )
}

fn assert_down_and_back(events: &[String], crossings: u32, what: &str) {
    let changes: Vec<&String> = events
        .iter()
        .filter(|e| e.contains("changed lanes"))
        .collect();
    assert_eq!(changes.len(), 2, "{what}: {events:?}");
    assert!(
        changes[0].contains("weaver changed lanes right, from lane 1 to lane 2"),
        "{what}: {changes:?}"
    );
    assert!(
        changes[1].contains("weaver changed lanes left, from lane 2 to lane 1"),
        "{what}: {changes:?}"
    );
    assert_eq!(crossings, 2, "{what}");
}

#[test]
fn a_lane_change_down_and_back_up_gives_two_events_on_the_straight_road() {
    // The upper lane starts at x = −50 m: s = 40 m is x = −10 m. Start at x = −40 m.
    let (events, crossings) = events_of(SimConfig::default(), -40.0);
    assert_down_and_back(&events, crossings, "straight");
}

#[test]
fn a_lane_change_down_and_back_up_gives_two_events_on_a_curve() {
    let config = SimConfig {
        lane_road: Some(LaneRoadConfig {
            curved_merge: Some(CurvedMergeConfig { radius_m: 300.0 }),
            ..LaneRoadConfig::default()
        }),
        ..SimConfig::default()
    };
    // On a road of lanes x_m is the arc length along the start lane.
    let (events, crossings) = events_of(config, 10.0);
    assert_down_and_back(&events, crossings, "curved");
}
