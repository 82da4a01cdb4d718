//! The drivable lanes of an OpenDRIVE network as a [`LaneRoadSpec`] (the crate docs say how).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mergesim_types::lanes::{LaneId, LaneKind, LaneRoad, LaneRoadSpec, LaneSpec, LaneTolerances};
use serde::Serialize;
use xodr::{Direction, Layer, RoadNetwork};

use crate::error::OpenDriveError;

/// Most drivable lanes a file may give (as many lanelets as a CommonRoad file may hold).
pub const MAX_LANES: usize = 5000;

/// Largest |x| or |y| of a lane accepted (m): the importer computes in `f32`, whose spacing is
/// 7.8 mm at 100 km (0.5 m at a UTM northing of 5,300 km).
pub const MAX_COORDINATE_M: f64 = 100_000.0;

/// Longest OpenDRIVE file read (bytes).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Where a mergesim lane came from in the OpenDRIVE file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct LaneOrigin {
    /// The mergesim lane id.
    pub id: u32,
    /// The `<road id>` it belongs to.
    pub road_id: String,
    /// The zero-based lane-section index within that road.
    pub section: usize,
    /// The OpenDRIVE `<lane id>` (negative right of the reference line, positive left).
    pub od_lane_id: i32,
    /// The OpenDRIVE lane type (`driving`, `entry`, …).
    pub lane_type: String,
}

/// An OpenDRIVE file's road: the lane description and where each lane came from.
#[derive(Clone, Debug)]
pub struct OpenDriveRoad {
    /// The file.
    pub path: PathBuf,
    /// The drivable lanes as mergesim lanes.
    pub spec: LaneRoadSpec,
    /// Each mergesim lane's OpenDRIVE origin, in id order.
    pub lanes: Vec<LaneOrigin>,
}

impl OpenDriveRoad {
    /// Builds the road of lanes.
    ///
    /// # Errors
    /// [`OpenDriveError::Road`] naming the lane (its mergesim id and OpenDRIVE origin) when the
    /// lanes do not make a consistent road.
    pub fn lane_road(&self) -> Result<LaneRoad, OpenDriveError> {
        LaneRoad::new(&self.spec).map_err(|e| {
            let origin = self
                .lanes
                .iter()
                .find(|o| e.to_string().starts_with(&format!("lane {}:", o.id)))
                .map(|o| {
                    format!(
                        "road {} section {} lane {}",
                        o.road_id, o.section, o.od_lane_id
                    )
                })
                .unwrap_or_else(|| "the lane network".into());
            OpenDriveError::Road {
                path: self.path.clone(),
                origin,
                error: e,
            }
        })
    }
}

/// Reads an OpenDRIVE file (at most [`MAX_FILE_BYTES`]).
///
/// # Errors
/// The file cannot be read, the importer refuses it, or it has no (or too many) drivable lanes.
pub fn read_file(path: &Path) -> Result<OpenDriveRoad, OpenDriveError> {
    let text = mergesim_types::files::read_regular_text(path, MAX_FILE_BYTES).map_err(|error| {
        OpenDriveError::Io {
            path: path.to_path_buf(),
            error,
        }
    })?;
    read_str(&text, path)
}

/// Reads an OpenDRIVE document; `path` names it in errors. An `<include>` is not followed.
///
/// # Errors
/// As [`read_file`].
pub fn read_str(text: &str, path: &Path) -> Result<OpenDriveRoad, OpenDriveError> {
    let (net, provenance) =
        xodr::load_str_with_provenance(text).map_err(|e| OpenDriveError::Import {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    // Faults the importer worked around that change the lanes (a dropped road, geometry,
    // lane section, lane or lane link, an unreadable value): the road would silently differ
    // from the file, so it is refused ([`changes_the_lanes`]).
    let faults: Vec<&xodr::Warning> = provenance
        .warnings
        .iter()
        .filter(|w| changes_the_lanes(w))
        .collect();
    if let Some(fault) = faults.first() {
        let more = faults.len() - 1;
        return Err(OpenDriveError::Fault {
            path: path.to_path_buf(),
            message: fault.to_string(),
            more,
        });
    }
    let origin_of: BTreeMap<usize, &xodr::LaneProvenance> =
        provenance.lanes.iter().map(|p| (p.lane.0, p)).collect();
    let drivable: Vec<&xodr::Lane> = net
        .lanes()
        .iter()
        .filter(|l| l.kind.is_drivable() && l.layer == Layer::Permanent)
        .filter(|l| l.direction != Direction::Both)
        .filter(|l| l.center.points().len() >= 2)
        .collect();
    if drivable.is_empty() {
        return Err(OpenDriveError::NoDrivableLane {
            path: path.to_path_buf(),
        });
    }
    if drivable.len() > MAX_LANES {
        return Err(OpenDriveError::TooManyLanes {
            path: path.to_path_buf(),
            count: drivable.len(),
            limit: MAX_LANES,
        });
    }
    // xodr lane index → mergesim id.
    let ids: BTreeMap<usize, LaneId> = drivable
        .iter()
        .enumerate()
        .map(|(i, l)| (l.id.0, LaneId(u32::try_from(i + 1).unwrap_or(u32::MAX))))
        .collect();
    let map_ids = |list: &[xodr::LaneId]| -> Vec<LaneId> {
        list.iter()
            .filter_map(|id| ids.get(&id.0).copied())
            .collect()
    };
    let mut specs = Vec::with_capacity(drivable.len());
    let mut origins = Vec::with_capacity(drivable.len());
    for lane in &drivable {
        let id = ids[&lane.id.0];
        let (centreline_m, half_width_m) = travel_polyline(lane);
        let (left, right) = sided_neighbours(&net, lane, &centreline_m, &ids);
        let kind = match lane.kind {
            xodr::LaneType::Entry | xodr::LaneType::OnRamp => LaneKind::Entry,
            xodr::LaneType::Exit | xodr::LaneType::OffRamp => LaneKind::Exit,
            _ => LaneKind::Main,
        };
        let prov = origin_of.get(&lane.id.0);
        let far_m = centreline_m
            .iter()
            .flat_map(|p| [p[0].abs(), p[1].abs()])
            .fold(0.0, f64::max);
        if far_m > MAX_COORDINATE_M {
            let resolution_m = f64::from(f32::EPSILON) * far_m;
            return Err(OpenDriveError::TooFarFromOrigin {
                path: path.to_path_buf(),
                origin: prov
                    .map(|p| format!("road {} lane {}", p.road_id, p.od_id))
                    .unwrap_or_else(|| "a lane".into()),
                coordinate_m: far_m,
                limit_m: MAX_COORDINATE_M,
                resolution_m,
            });
        }
        specs.push(LaneSpec {
            id,
            kind,
            centreline_m,
            width_m: Vec::new(),
            left_width_m: half_width_m.clone(),
            right_width_m: half_width_m,
            left,
            right,
            successors: map_ids(&lane.successors),
            predecessors: map_ids(&lane.predecessors),
        });
        origins.push(LaneOrigin {
            id: id.0,
            road_id: prov.map(|p| p.road_id.clone()).unwrap_or_default(),
            section: prov.map(|p| p.section).unwrap_or_default(),
            od_lane_id: prov.map(|p| p.od_id).unwrap_or_default(),
            lane_type: lane.kind.as_str().to_string(),
        });
    }
    Ok(OpenDriveRoad {
        path: path.to_path_buf(),
        spec: LaneRoadSpec {
            lanes: specs,
            tolerances: LaneTolerances {
                link_m: 0.5,
                ..LaneTolerances::default()
            },
        },
        lanes: origins,
    })
}

/// Whether an importer warning means the lanes differ from what the file says: a road,
/// geometry, lane section, lane, lane link, junction connection or neighbour dropped, a lane id
/// unreadable or repeated, a record value unreadable. Other warnings (features ignored, records
/// sorted, speed limits, objects, road marks, elevation) leave the lanes as written.
fn changes_the_lanes(w: &xodr::Warning) -> bool {
    use xodr::Warning as W;
    matches!(
        w,
        W::RoadSkipped { .. }
            | W::GeometryDropped { .. }
            | W::LaneSectionDropped { .. }
            | W::LaneDropped { .. }
            | W::LaneIdUnreadable { .. }
            | W::LaneIdRepeated { .. }
            | W::LaneLinkDropped { .. }
            | W::ConnectionDropped { .. }
            | W::NeighborDropped { .. }
            | W::RecordValueUnreadable { .. }
    )
}

/// The lane's centreline in travel direction and its half widths per vertex.
fn travel_polyline(lane: &xodr::Lane) -> (Vec<[f64; 2]>, Vec<f64>) {
    let points = lane.center.points();
    let mut centreline: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let mut half: Vec<f64> = (0..points.len())
        .map(|i| {
            let w = if lane.widths.is_empty() {
                lane.width
            } else {
                lane.widths
                    .get(i)
                    .or(lane.widths.last())
                    .copied()
                    .unwrap_or(lane.width)
            };
            0.5 * f64::from(w)
        })
        .collect();
    if lane.direction == Direction::Backward {
        centreline.reverse();
        half.reverse();
    }
    (centreline, half)
}

/// The same-direction neighbours on the left and on the right: a neighbour whose centreline
/// point nearest to this lane's middle vertex lies left of the lane's travel direction is the
/// left one.
fn sided_neighbours(
    net: &RoadNetwork,
    lane: &xodr::Lane,
    centreline: &[[f64; 2]],
    ids: &BTreeMap<usize, LaneId>,
) -> (Option<LaneId>, Option<LaneId>) {
    let mid = centreline.len() / 2;
    let (a, b) = if mid + 1 < centreline.len() {
        (centreline[mid], centreline[mid + 1])
    } else {
        (centreline[mid - 1], centreline[mid])
    };
    let tangent = [b[0] - a[0], b[1] - a[1]];
    let (mut left, mut right) = (None, None);
    for n in &lane.neighbors {
        let (Some(&id), Some(other)) = (ids.get(&n.0), net.lane(*n)) else {
            continue;
        };
        let nearest = other
            .center
            .points()
            .iter()
            .map(|p| [f64::from(p.x), f64::from(p.y)])
            .min_by(|p, q| {
                let dp = (p[0] - a[0]).hypot(p[1] - a[1]);
                let dq = (q[0] - a[0]).hypot(q[1] - a[1]);
                dp.total_cmp(&dq)
            });
        let Some(p) = nearest else { continue };
        let cross = tangent[0] * (p[1] - a[1]) - tangent[1] * (p[0] - a[0]);
        if cross > 0.0 {
            left = left.or(Some(id));
        } else {
            right = right.or(Some(id));
        }
    }
    (left, right)
}
