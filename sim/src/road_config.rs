//! The scenario's road as lanes: the `[sim.lane_road]` table, the alternative to the parametric
//! `[sim.road]` merge road, and a vehicle's start lane.
//!
//! A scenario's road is a road of lanes ([`LaneRoad`]). It comes from one of:
//! - `[sim.road]` alone (the paper's straight merge road, [`MergeRoad::lane_road`]): lanes 1
//!   (the through lane, `"upper"`) and 2 (the ending lane, `"lower"`);
//! - `[sim.lane_road]` with `curved_merge = { radius_m = R }`: the `[sim.road]` merge road bent
//!   on a circular arc of radius R (left turn for R > 0; [`curved_merge_spec`]), same lane ids;
//! - `[sim.lane_road]` with `on_ramp = { … }`: a two-lane main road with a parallel
//!   acceleration lane entered from a ramp ([`on_ramp_spec`]; lanes 1, 2 main, 3 acceleration,
//!   4 ramp);
//! - `[sim.lane_road]` with `[[sim.lane_road.lanes]]`: lanes written out as polylines with widths
//!   and links ([`LaneSpec`]), and optional `[sim.lane_road.tolerances]`;
//! - `[sim.lane_road]` with `commonroad = { file = "…", recorded_traffic = "replay" }`: the
//!   lanelet network of a CommonRoad file ([`CommonRoadRoad`]; `mergesim_commonroad::road`),
//!   lanelet ids as lane ids. A scenario TOML writes it as `[sim.road] commonroad = "…"`
//!   (docs/commonroad.md); `--scenario FILE.xml` builds it.
//!
//! - `[sim.lane_road]` with `opendrive = { file = "…" }`: the drivable lanes of an OpenDRIVE
//!   file ([`OpenDriveRoadSource`]; `mergesim_opendrive`), lane ids as `merge_sim opendrive
//!   dump` lists them; the file is relative to the TOML (docs/opendrive.md).
//!
//! Exactly one of `curved_merge`, `on_ramp`, `lanes`, `commonroad` and `opendrive` is given in
//! `[sim.lane_road]`.

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

use mergesim_types::lanes::{
    LaneId, LaneRoad, LaneRoadSpec, LaneSpec, LaneTolerances, OnRampParams, curved_merge_spec,
    on_ramp_spec,
};
use mergesim_types::{InvalidParameter, Lane, MergeRoad};
use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::SimError;
use crate::recorded_traffic::TrafficMode;

/// The merge road of `[sim.road]` bent on a circular arc.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvedMergeConfig {
    /// Radius of the lane divider's arc (m); positive turns left, negative right.
    pub radius_m: f64,
}

/// A road read from a CommonRoad file's lanelet network.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommonRoadRoad {
    /// The CommonRoad XML file (the scenario loader makes it absolute; a path written in a
    /// scenario TOML is relative to the TOML).
    pub file: PathBuf,
    /// How the file's obstacles move (`none`, `replay`, `reactive`); the loader fills
    /// `SimConfig::recorded_traffic` with them in this mode.
    #[serde(default)]
    pub recorded_traffic: TrafficMode,
    /// The lanes read from the file, kept by the loader so that checks do not read it again.
    #[serde(skip)]
    pub cached_spec: Option<Arc<LaneRoadSpec>>,
}

impl CommonRoadRoad {
    /// A road read from `file`, with its lanes read now and kept.
    pub fn read(file: PathBuf, recorded_traffic: TrafficMode) -> Result<Self, SimError> {
        let scenario = mergesim_commonroad::read_file(&file)?;
        Ok(Self::of(file, recorded_traffic, &scenario))
    }

    /// The road of a file already read.
    pub fn of(
        file: PathBuf,
        recorded_traffic: TrafficMode,
        scenario: &mergesim_commonroad::model::Scenario,
    ) -> Self {
        Self {
            file,
            recorded_traffic,
            cached_spec: Some(Arc::new(mergesim_commonroad::road::lane_road_spec(
                scenario,
            ))),
        }
    }

    /// Its lanes (the kept ones, else read from the file).
    pub fn spec(&self) -> Result<LaneRoadSpec, SimError> {
        match &self.cached_spec {
            Some(spec) => Ok(LaneRoadSpec::clone(spec)),
            None => {
                let scenario = mergesim_commonroad::read_file(&self.file)?;
                Ok(mergesim_commonroad::road::lane_road_spec(&scenario))
            }
        }
    }
}

/// A road read from an OpenDRIVE file's drivable lanes (`mergesim_opendrive`; lane ids as
/// `merge_sim opendrive dump` lists them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpenDriveRoadSource {
    /// The OpenDRIVE file (the scenario loader makes it absolute; a path written in a scenario
    /// TOML is relative to the TOML).
    pub file: PathBuf,
    /// The lanes read from the file, kept by the loader so that checks do not read it again.
    #[serde(skip)]
    pub cached_spec: Option<Arc<LaneRoadSpec>>,
}

impl OpenDriveRoadSource {
    /// A road read from `file` now, its lanes kept.
    pub fn read(file: PathBuf) -> Result<Self, SimError> {
        let road = mergesim_opendrive::read_file(&file)?;
        road.lane_road()?;
        Ok(Self {
            file,
            cached_spec: Some(Arc::new(road.spec)),
        })
    }

    /// Its lanes (the kept ones, else read from the file).
    pub fn spec(&self) -> Result<LaneRoadSpec, SimError> {
        match &self.cached_spec {
            Some(spec) => Ok(LaneRoadSpec::clone(spec)),
            None => Ok(mergesim_opendrive::read_file(&self.file)?.spec),
        }
    }
}

/// `[sim.lane_road]`: a road of lanes instead of the straight `[sim.road]` merge road (module
/// doc). Exactly one of `curved_merge`, `on_ramp`, `lanes`, `commonroad`, `opendrive`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaneRoadConfig {
    /// The `[sim.road]` merge road bent on an arc.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curved_merge: Option<CurvedMergeConfig>,
    /// An on-ramp with a parallel acceleration lane.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on_ramp: Option<OnRampParams>,
    /// Lanes written out: polylines with widths and links.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lanes: Vec<LaneSpec>,
    /// Cleaning and checking tolerances of written-out lanes.
    #[serde(default)]
    pub tolerances: LaneTolerances,
    /// A CommonRoad file's lanelet network.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commonroad: Option<CommonRoadRoad>,
    /// An OpenDRIVE file's drivable lanes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opendrive: Option<OpenDriveRoadSource>,
}

/// Prefixes an invalid parameter's dotted name (`radius_m` → `lane_road.curved_merge.radius_m`).
fn renamed(e: InvalidParameter, prefix: &str, strip: &str) -> SimError {
    let name = e.name.strip_prefix(strip).unwrap_or(&e.name);
    SimError::InvalidParameter(InvalidParameter::new(
        format!("{prefix}{name}"),
        e.value,
        e.reason,
    ))
}

impl LaneRoadConfig {
    /// The lane description it stands for; `road` is the `[sim.road]` table (bent by
    /// `curved_merge`). Refuses a table giving none or more than one road, naming the field.
    pub fn spec(&self, road: &MergeRoad) -> Result<LaneRoadSpec, SimError> {
        let given = [
            self.curved_merge.is_some(),
            self.on_ramp.is_some(),
            !self.lanes.is_empty(),
            self.commonroad.is_some(),
            self.opendrive.is_some(),
        ];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(SimError::InvalidField {
                field: "lane_road".into(),
                message: "give exactly one of lane_road.curved_merge, lane_road.on_ramp, \
                          [[sim.lane_road.lanes]], lane_road.commonroad and lane_road.opendrive"
                    .into(),
            });
        }
        if let Some(c) = &self.commonroad {
            return c.spec();
        }
        if let Some(o) = &self.opendrive {
            return o.spec();
        }
        if let Some(c) = &self.curved_merge {
            return curved_merge_spec(road, c.radius_m).map_err(|e| {
                if e.name.starts_with("road.") {
                    SimError::InvalidParameter(e)
                } else {
                    renamed(e, "lane_road.curved_merge.", "")
                }
            });
        }
        if let Some(p) = &self.on_ramp {
            return on_ramp_spec(p).map_err(|e| renamed(e, "lane_road.on_ramp.", "on_ramp."));
        }
        Ok(LaneRoadSpec {
            lanes: self.lanes.clone(),
            tolerances: self.tolerances.clone(),
        })
    }

    /// True if the road is the `[sim.road]` merge road's lanes (straight or bent), so that
    /// `"lower"` and `"upper"` and the merge section keep their meaning.
    pub fn is_merge_road(&self) -> bool {
        self.curved_merge.is_some()
    }
}

/// The lane a vehicle starts in: `"lower"` / `"upper"` (the merge road's ending lane, id 2, and
/// through lane, id 1), or a lane id of a road of lanes (an integer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartLane {
    /// A lane of the merge road by name.
    Named(Lane),
    /// A lane by id.
    Id(LaneId),
}

impl StartLane {
    /// The merge road's lane it names (`"upper"` or id 1, `"lower"` or id 2), if any.
    pub fn merge_lane(self) -> Option<Lane> {
        match self {
            StartLane::Named(lane) => Some(lane),
            StartLane::Id(id) if id == MergeRoad::lane_id(Lane::Upper) => Some(Lane::Upper),
            StartLane::Id(id) if id == MergeRoad::lane_id(Lane::Lower) => Some(Lane::Lower),
            StartLane::Id(_) => None,
        }
    }

    /// The lane's id in the road of lanes (`"upper"` = 1, `"lower"` = 2).
    pub fn id(self) -> LaneId {
        match self {
            StartLane::Named(lane) => MergeRoad::lane_id(lane),
            StartLane::Id(id) => id,
        }
    }
}

impl From<Lane> for StartLane {
    fn from(lane: Lane) -> Self {
        StartLane::Named(lane)
    }
}

impl From<LaneId> for StartLane {
    fn from(id: LaneId) -> Self {
        StartLane::Id(id)
    }
}

impl PartialEq<Lane> for StartLane {
    fn eq(&self, other: &Lane) -> bool {
        *self == StartLane::Named(*other)
    }
}

impl fmt::Display for StartLane {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StartLane::Named(Lane::Lower) => write!(f, "lower"),
            StartLane::Named(Lane::Upper) => write!(f, "upper"),
            StartLane::Id(id) => write!(f, "{id}"),
        }
    }
}

impl Serialize for StartLane {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            StartLane::Named(lane) => lane.serialize(serializer),
            StartLane::Id(id) => serializer.serialize_u32(id.0),
        }
    }
}

struct StartLaneVisitor;

impl Visitor<'_> for StartLaneVisitor {
    type Value = StartLane;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "\"lower\", \"upper\" or a lane id (a non-negative integer)"
        )
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<StartLane, E> {
        match v {
            "lower" => Ok(StartLane::Named(Lane::Lower)),
            "upper" => Ok(StartLane::Named(Lane::Upper)),
            other => Err(E::invalid_value(de::Unexpected::Str(other), &self)),
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<StartLane, E> {
        u32::try_from(v)
            .map(|id| StartLane::Id(LaneId(id)))
            .map_err(|_| E::invalid_value(de::Unexpected::Unsigned(v), &self))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<StartLane, E> {
        u32::try_from(v)
            .map(|id| StartLane::Id(LaneId(id)))
            .map_err(|_| E::invalid_value(de::Unexpected::Signed(v), &self))
    }
}

impl<'de> Deserialize<'de> for StartLane {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(StartLaneVisitor)
    }
}

/// Builds the road of lanes of a configuration (see the module doc).
pub fn build_lane_road(
    road: &MergeRoad,
    lane_road: Option<&LaneRoadConfig>,
) -> Result<LaneRoad, SimError> {
    match lane_road {
        None => Ok(road.lane_road()?),
        Some(c) => Ok(LaneRoad::new(&c.spec(road)?)?),
    }
}
