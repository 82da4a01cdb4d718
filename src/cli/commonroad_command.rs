//! `merge_sim commonroad dump FILE.xml`: what the CommonRoad reader reads, as JSON.

use std::collections::BTreeMap;

use mergesim_commonroad::model::{ReplayState, Scenario};
use mergesim_commonroad::read_with_road;
use mergesim_types::lanes::LaneRoadSpec;
use serde::Serialize;

use crate::cli::args::CommonroadCommand;
use crate::cli::{Failure, input, out, run_failure};

/// The JSON of `merge_sim commonroad dump`.
#[derive(Serialize)]
struct Dump<'a> {
    /// The file's content as read.
    scenario: &'a Scenario,
    /// Each obstacle's initial state then trajectory states in replay form, by obstacle id.
    replay: BTreeMap<i64, Vec<ReplayState>>,
    /// The road of lanes built from the lanelet network (accepted by the lane road).
    lane_road: LaneRoadSpec,
}

pub(crate) fn cmd_commonroad(cmd: &CommonroadCommand) -> Result<(), Failure> {
    match cmd {
        CommonroadCommand::Dump { file } => {
            let (scenario, _road) = read_with_road(file).map_err(input)?;
            let replay = scenario
                .dynamic_obstacles
                .iter()
                .chain(&scenario.static_obstacles)
                .map(|o| {
                    let states = std::iter::once(&o.initial_state)
                        .chain(&o.trajectory)
                        .filter_map(|s| s.replay(scenario.time_step_s))
                        .collect();
                    (o.id, states)
                })
                .collect();
            let dump = Dump {
                scenario: &scenario,
                replay,
                lane_road: mergesim_commonroad::road::lane_road_spec(&scenario),
            };
            let json = serde_json::to_string_pretty(&dump).map_err(run_failure)?;
            out!("{json}\n");
            Ok(())
        }
    }
}
