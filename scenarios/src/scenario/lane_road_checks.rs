//! The checks of a scenario whose road is a road of lanes (`[sim.lane_road]`): where a lane
//! error sits in the file, the spawn geometry in the lanes' frames, and one road per scenario.

use mergesim_types::lanes::{LaneError, LaneId, LaneRoad};

use super::{Line, Scenario, ScenarioError};
use crate::oriented_box::OrientedBox;
use crate::source_location::line_of;

impl Scenario {
    /// The TOML path and the dotted field of a lane error: the lane's entry in
    /// `[[sim.lane_road.lanes]]` (the second one for a duplicate id) and its field (with the
    /// vertex index where the error names one), or `[sim.lane_road]` for a generated road.
    pub(super) fn lane_error_path(&self, e: &LaneError) -> (Vec<String>, String) {
        let lanes = self
            .sim
            .lane_road
            .as_ref()
            .map(|c| &c.lanes[..])
            .unwrap_or(&[]);
        let mut path = vec!["sim".to_string(), "lane_road".to_string()];
        let index = e.lane().and_then(|id| {
            let mut matches = lanes.iter().enumerate().filter(|(_, l)| l.id == id);
            let first = matches.next().map(|(i, _)| i);
            if matches!(e, LaneError::DuplicateId { .. }) {
                matches.next().map(|(i, _)| i).or(first)
            } else {
                first
            }
        });
        let Some(index) = index else {
            if matches!(e, LaneError::BadTolerance { .. }) {
                path.extend(["tolerances".to_string(), e.field().to_string()]);
                return (path, format!("lane_road.tolerances.{}", e.field()));
            }
            if lanes.is_empty() {
                return (path, "lane_road".into());
            }
            path.push("lanes".into());
            return (path, "lane_road.lanes".into());
        };
        path.extend([
            "lanes".to_string(),
            index.to_string(),
            e.field().to_string(),
        ]);
        let vertex = match e {
            LaneError::NonFinite { index, .. }
            | LaneError::SharpTurn { index, .. }
            | LaneError::NonPositiveWidth { index, .. } => Some(*index),
            _ => None,
        };
        let mut field = format!("lane_road.lanes[{index}].{}", e.field());
        // A width list of one value stands for every vertex.
        if let Some(vertex) = vertex {
            let entries = lanes.get(index).map_or(0, |l| match e.field() {
                "centreline_m" => l.centreline_m.len(),
                "width_m" => l.width_m.len(),
                "left_width_m" => l.left_width_m.len(),
                "right_width_m" => l.right_width_m.len(),
                _ => 0,
            });
            if vertex < entries {
                path.push(vertex.to_string());
                field = format!("{field}[{vertex}]");
            }
        }
        (path, field)
    }

    /// Spawn geometry on a road of lanes: each vehicle's body, over its randomisation box, lies
    /// on the drivable area (its four corners do, each at the lane's heading where it stands),
    /// and no two bodies can overlap (oriented boxes covering each body's randomisation range).
    /// The lanes must be long enough for the run: every vehicle driving the whole duration at the
    /// highest speed it starts at, aims at or is prescribed (+ `ROAD_END_SPEED_ALLOWANCE`) stays
    /// short of the open end of the lanes ahead of it ([`drivable_ahead_m`]).
    pub(super) fn check_lane_geometry(
        &self,
        origin: &str,
        at: &dyn Fn(Option<Vec<String>>) -> Line,
    ) -> Result<(), ScenarioError> {
        let lanes = self.sim.lanes().map_err(|e| ScenarioError::Invalid {
            origin: origin.to_string(),
            line: at(Some(vec!["sim".into(), "lane_road".into()])),
            field: Some("lane_road".into()),
            message: e.to_string(),
        })?;
        let mut boxes: Vec<(String, OrientedBox)> = Vec::with_capacity(self.vehicles.len());
        for v in &self.vehicles {
            let field_path = |key: &str| {
                self.randomise
                    .vehicle_entry_path(&v.name, key)
                    .or_else(|| self.nominal_path(&format!("vehicles[{}].{key}", v.name)))
            };
            let invalid = |key: &str, message: String| ScenarioError::Invalid {
                origin: origin.to_string(),
                line: at(field_path(key)),
                field: Some(format!("vehicles[{}].{key}", v.name)),
                message: format!("vehicles[{}].{key}: {message}", v.name),
            };
            let params = vehicles::VehicleParams::preset(&v.preset)
                .map_err(|e| invalid("preset", e.to_string()))?;
            let Some(lane) = lanes.lane(v.lane.id()) else {
                return Err(invalid(
                    "lane",
                    format!("lane {} is not on the road", v.lane),
                ));
            };
            let b = self.randomise.vehicle_bounds(&v.name);
            let (half_l, half_w) = (0.5 * params.length_m, 0.5 * params.width_m);
            let s_range = [v.x_m + b.x_m[0], v.x_m + b.x_m[1]];
            let d_range = [
                v.y_offset_m + b.y_offset_m[0],
                v.y_offset_m + b.y_offset_m[1],
            ];
            // Corners at every metre of the s range (and its ends), at both ends of the d range.
            let steps = ((s_range[1] - s_range[0]).ceil().max(0.0) as usize).min(10_000) + 1;
            for k in 0..=steps {
                let s = s_range[0] + (s_range[1] - s_range[0]) * k as f64 / steps as f64;
                for d in d_range {
                    let body = OrientedBox::on_lane(lane, s, d, half_l, half_w);
                    if let Some(corner) =
                        body.corners().into_iter().find(|c| !lanes.is_drivable(*c))
                    {
                        // Off the side with the nominal offset too: the position along the lane is
                        // the cause.
                        let centred = OrientedBox::on_lane(lane, s, 0.0, half_l, half_w);
                        let lateral = centred.corners().iter().all(|c| lanes.is_drivable(*c));
                        let key = if lateral { "y_offset_m" } else { "x_m" };
                        return Err(invalid(
                            key,
                            format!(
                                "the body must lie on the road at spawn, including randomisation: \
                                 at s = {s:.3} m, d = {d:.3} m on lane {} its corner \
                                 ({:.3}, {:.3}) m is off the road",
                                v.lane, corner[0], corner[1]
                            ),
                        ));
                    }
                }
            }
            // One box covering the body over the whole range (at the range's middle heading).
            let s_mid = 0.5 * (s_range[0] + s_range[1]);
            let d_mid = 0.5 * (d_range[0] + d_range[1]);
            let swept = OrientedBox::on_lane(
                lane,
                s_mid,
                d_mid,
                half_l + 0.5 * (s_range[1] - s_range[0]),
                half_w + 0.5 * (d_range[1] - d_range[0]),
            );
            for (other, ob) in &boxes {
                if swept.overlaps(ob) {
                    return Err(invalid(
                        "x_m",
                        format!(
                            "x_m = {}: its body can overlap that of vehicle {other} at spawn \
                             (including randomisation)",
                            v.x_m
                        ),
                    ));
                }
            }
            boxes.push((v.name.clone(), swept));
            let top_speed_mps = super::top_speed_mps(v, &b);
            // On a CommonRoad road a vehicle may drive off the map: that ends the run with an
            // event (`sim::world`), as CommonRoad's maps end where their recordings do.
            if self.sim.commonroad_road().is_some() {
                continue;
            }
            let needed_m = half_l + top_speed_mps * self.sim.duration_s;
            let ahead_m = drivable_ahead_m(&lanes, v.lane.id(), s_range[1]);
            if needed_m > ahead_m {
                return Err(ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(self.nominal_path("duration_s")),
                    field: Some("duration_s".into()),
                    message: format!(
                        "duration_s = {} s: the lanes are too short for vehicles[{}], which can \
                         drive {needed_m:.1} m (its front, at {top_speed_mps:.2} m/s = its \
                         highest initial, target or prescribed speed including randomisation, \
                         + {:.0} %) while the lanes ahead of it end after {ahead_m:.1} m; \
                         lengthen the road or shorten the run",
                        self.sim.duration_s,
                        v.name,
                        100.0 * super::ROAD_END_SPEED_ALLOWANCE
                    ),
                });
            }
        }
        Ok(())
    }
}

/// How far a vehicle at arc length `s_m` of lane `lane` can drive before the road's open end:
/// along the lane, then its longest successor chain; where a lane ends closed, on along the
/// neighbour it merges into (left, else right) from beside its end. Each lane is visited once.
pub(super) fn drivable_ahead_m(lanes: &LaneRoad, lane: LaneId, s_m: f64) -> f64 {
    fn ahead(lanes: &LaneRoad, lane: LaneId, s_m: f64, visited: &mut Vec<LaneId>) -> f64 {
        let Some(l) = lanes.lane(lane) else {
            return 0.0;
        };
        if visited.contains(&lane) {
            return 0.0;
        }
        visited.push(lane);
        let here_m = (l.length_m() - s_m).max(0.0);
        let next_m = if !l.successors().is_empty() {
            l.successors()
                .iter()
                .map(|n| ahead(lanes, *n, 0.0, visited))
                .fold(0.0, f64::max)
        } else if lanes.lane_end(lane).is_some_and(|e| e.closed) {
            match l.left_neighbour().or(l.right_neighbour()) {
                Some(nb) => {
                    let end_m = l.point(l.length_m(), 0.0);
                    let s_nb = lanes.lane(nb).map_or(0.0, |n| n.project(end_m).s_m);
                    ahead(lanes, nb, s_nb, visited)
                }
                None => 0.0,
            }
        } else {
            0.0
        };
        visited.pop();
        here_m + next_m
    }
    ahead(lanes, lane, s_m, &mut Vec::new())
}

/// `[sim.road]` and a `[sim.lane_road]` that does not bend it (`on_ramp`, `lanes`) cannot both
/// be given: refused at `[sim.lane_road]`'s line.
pub(super) fn check_one_road(
    table: &toml::Table,
    scenario: &Scenario,
    origin: &str,
    text: &str,
) -> Result<(), ScenarioError> {
    let sim = table.get("sim").and_then(|s| s.as_table());
    let has = |key: &str| sim.is_some_and(|s| s.contains_key(key));
    let bends = scenario
        .sim
        .lane_road
        .as_ref()
        .is_some_and(|c| c.is_merge_road());
    if has("road") && has("lane_road") && !bends {
        return Err(ScenarioError::Invalid {
            origin: origin.to_string(),
            line: Line(line_of(text, &["sim".to_string(), "lane_road".to_string()])),
            field: Some("lane_road".into()),
            message: "[sim.road] and [sim.lane_road] both give the road: keep one (only \
                      lane_road.curved_merge bends [sim.road])"
                .into(),
        });
    }
    Ok(())
}
