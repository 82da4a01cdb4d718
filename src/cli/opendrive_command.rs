//! `merge_sim opendrive dump FILE.xodr`: the road of lanes taken from an OpenDRIVE file, as JSON.

use mergesim_opendrive::{LaneOrigin, read_file};
use mergesim_types::lanes::LaneRoadSpec;
use serde::Serialize;

use crate::cli::args::OpendriveCommand;
use crate::cli::{Failure, input, out, run_failure};

/// The JSON of `merge_sim opendrive dump`.
#[derive(Serialize)]
struct Dump<'a> {
    /// Each mergesim lane's OpenDRIVE origin, in id order.
    lanes: &'a [LaneOrigin],
    /// The road of lanes (accepted by the lane road).
    lane_road: &'a LaneRoadSpec,
}

pub(crate) fn cmd_opendrive(cmd: &OpendriveCommand) -> Result<(), Failure> {
    match cmd {
        OpendriveCommand::Dump { file } => {
            let road = read_file(file).map_err(input)?;
            road.lane_road().map_err(input)?;
            let json = serde_json::to_string_pretty(&Dump {
                lanes: &road.lanes,
                lane_road: &road.spec,
            })
            .map_err(run_failure)?;
            out!("{json}\n");
            Ok(())
        }
    }
}
