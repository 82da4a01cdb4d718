//! A CommonRoad file as a scenario (`--scenario FILE.xml`; docs/commonroad.md):
//!
//! - **road**: the lanelet network ([`sim::road_config::CommonRoadRoad`]), lanelet ids as lane ids, in the
//!   file's coordinates;
//! - **recorded traffic** ([`recorded_traffic`]): every dynamic obstacle (its initial state and
//!   trajectory in replay form) and every static obstacle (its initial state, held for the whole
//!   run), named `cr-<id>`, times relative to the run's start (the planning problem's initial
//!   time step); mode `replay` unless asked otherwise;
//! - **ego** ([`ego_of`]): the first planning problem's initial state: its lane is the lanelet
//!   holding its position (the one whose heading is closest to its orientation where lanelets
//!   overlap), s and d in that lane's frame, its speed; the default preset (`bmw_320i`) driven by
//!   `pf-iso` (`--planner` overrides it); its goal ([`goal_of`]) and its route to it
//!   ([`sim::route::shortest_route`]); the target speed is the goal's velocity interval's
//!   midpoint, else the speed limit of the first lanelet on its route that has one, else its
//!   initial speed;
//! - **duration**: until the goal's time interval ends, else the last recorded state, else
//!   `SimConfig`'s default; `--duration` overrides it.

use std::path::{Path, PathBuf};

use mergesim_commonroad::model::{self, Position, Shape, Value};
use mergesim_types::lanes::{LaneId, LaneRoad};
use sim::config::{Driver, SimConfig, VehicleSpec};
use sim::goal::{Goal, GoalPosition, GoalShape, GoalState, Interval};
use sim::recorded_traffic::{RecordedState, RecordedTraffic, RecordedVehicle, TrafficMode};
use sim::road_config::{CommonRoadRoad, LaneRoadConfig, StartLane};

use crate::scenario::{Line, Scenario, ScenarioError};

/// The preset of the ego of a CommonRoad scenario.
pub const EGO_PRESET: &str = "bmw_320i";
/// The planner of the ego of a CommonRoad scenario (`--planner` overrides it).
pub const EGO_PLANNER: &str = "pf-iso";

/// A refusal naming the file, the line and the element.
fn invalid(path: &Path, line: u32, element: String, message: String) -> ScenarioError {
    ScenarioError::Invalid {
        origin: path.display().to_string(),
        line: Line(Some(line as usize)),
        message: format!("{element}: {message}"),
        field: Some(element),
    }
}

/// The absolute form of `path` (made absolute against the working directory if it does not
/// exist, so that the reader's own error names it).
pub(crate) fn absolute(path: &Path) -> PathBuf {
    std::fs::canonicalize(path)
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

fn interval(v: Value, scale: f64, offset: f64) -> Interval {
    let (a, b) = match v {
        Value::Exact(x) => (x, x),
        Value::Interval { start, end } => (start, end),
    };
    Interval {
        start: a * scale - offset,
        end: b * scale - offset,
    }
}

fn goal_shape(s: &Shape) -> GoalShape {
    match s {
        Shape::Rectangle {
            length_m,
            width_m,
            orientation_rad,
            center_m,
        } => GoalShape::Rectangle {
            length_m: *length_m,
            width_m: *width_m,
            orientation_rad: *orientation_rad,
            center_m: *center_m,
        },
        Shape::Circle { radius_m, center_m } => GoalShape::Circle {
            radius_m: *radius_m,
            center_m: *center_m,
        },
        Shape::Polygon { vertices_m } => GoalShape::Polygon {
            vertices_m: vertices_m.clone(),
        },
    }
}

/// The goal of a planning problem: its goal states with times in seconds since the run's start
/// (`t0_s`, the initial state's time).
pub fn goal_of(pp: &model::PlanningProblem, time_step_s: f64, t0_s: f64) -> Goal {
    Goal {
        states: pp
            .goal_states
            .iter()
            .map(|g| GoalState {
                time_s: g.time_step.map(|v| interval(v, time_step_s, t0_s)),
                position: g.position.as_ref().map(|p| match p {
                    Position::Point(q) => GoalPosition::Shapes(vec![GoalShape::Circle {
                        radius_m: 0.0,
                        center_m: *q,
                    }]),
                    Position::Shapes(shapes) => {
                        GoalPosition::Shapes(shapes.iter().map(goal_shape).collect())
                    }
                    Position::Lanelets(ids) => GoalPosition::Lanes(
                        ids.iter()
                            .map(|&id| LaneId(u32::try_from(id).unwrap_or(u32::MAX)))
                            .collect(),
                    ),
                }),
                orientation_rad: g.orientation_rad.map(|v| interval(v, 1.0, 0.0)),
                velocity_mps: g.velocity_mps.map(|v| interval(v, 1.0, 0.0)),
                source: format!("goalState on line {}", g.line),
            })
            .collect(),
    }
}

/// The lanes a goal state's position touches: its lanelets, or the lanes whose centreline
/// enters one of its shapes or that hold a shape's centre.
fn goal_lanes(position: &GoalPosition, lanes: &LaneRoad) -> Vec<LaneId> {
    match position {
        GoalPosition::Lanes(ids) => ids.clone(),
        GoalPosition::Shapes(shapes) => {
            let mut ids =
                sim::route::lanes_touching(lanes, |p| shapes.iter().any(|s| s.contains(p)));
            for s in shapes {
                for hit in lanes.lanes_at(s.center_m()) {
                    if !ids.contains(&hit.lane) {
                        ids.push(hit.lane);
                    }
                }
            }
            ids
        }
    }
}

/// The lane holding `p_m`: among the lanes holding it, the one whose heading there is closest
/// to `heading_rad`; with its (s, d).
fn lane_at(lanes: &LaneRoad, p_m: [f64; 2], heading_rad: f64) -> Option<(LaneId, f64, f64)> {
    let turn = std::f64::consts::TAU;
    let diff = |a: f64| {
        let d = (a - heading_rad).rem_euclid(turn);
        d.min(turn - d)
    };
    lanes
        .lanes_at(p_m)
        .into_iter()
        .filter_map(|hit| {
            let lane = lanes.lane(hit.lane)?;
            Some((
                diff(lane.heading_rad(hit.frame.s_m)),
                hit.lane,
                hit.frame.s_m,
                hit.frame.d_m,
            ))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, id, s, d)| (id, s, d))
}

/// The recorded traffic of a file (module doc), in `mode`; `t0_s` is the run's start in the
/// file's time.
pub fn recorded_traffic(
    path: &Path,
    cr: &model::Scenario,
    mode: TrafficMode,
    t0_s: f64,
) -> Result<RecordedTraffic, ScenarioError> {
    let mut vehicles = Vec::new();
    let obstacles = cr
        .dynamic_obstacles
        .iter()
        .map(|o| (o, "dynamicObstacle"))
        .chain(cr.static_obstacles.iter().map(|o| (o, "staticObstacle")));
    for (o, kind) in obstacles {
        let element = format!("{kind} {}", o.id);
        let (length_m, width_m) = match &o.shape {
            Shape::Rectangle {
                length_m, width_m, ..
            } => (*length_m, *width_m),
            Shape::Circle { radius_m, .. } => (2.0 * radius_m, 2.0 * radius_m),
            Shape::Polygon { vertices_m } => {
                let span = |k: usize| {
                    let lo = vertices_m
                        .iter()
                        .map(|p| p[k])
                        .fold(f64::INFINITY, f64::min);
                    let hi = vertices_m
                        .iter()
                        .map(|p| p[k])
                        .fold(f64::NEG_INFINITY, f64::max);
                    hi - lo
                };
                (span(0), span(1))
            }
        };
        let mut states: Vec<RecordedState> = Vec::with_capacity(o.trajectory.len() + 1);
        for s in std::iter::once(&o.initial_state).chain(&o.trajectory) {
            // A static obstacle's state may leave out its orientation and speed: 0.
            let r = match (
                s.time_step,
                s.position.as_ref().and_then(Position::replay_m),
            ) {
                (Some(t), Some(p)) => RecordedState {
                    time_s: t.midpoint() * cr.time_step_s - t0_s,
                    position_m: p,
                    heading_rad: s.orientation_rad.map_or(0.0, |v| v.midpoint()),
                    speed_mps: s.velocity_mps.map_or(0.0, |v| v.midpoint()),
                },
                _ => {
                    return Err(invalid(
                        path,
                        s.line,
                        element,
                        "a recorded state needs a time and a position".into(),
                    ));
                }
            };
            if let Some(last) = states.last()
                && r.time_s <= last.time_s
            {
                return Err(invalid(
                    path,
                    s.line,
                    element,
                    format!(
                        "its states' times must increase (t = {} s after t = {} s)",
                        r.time_s, last.time_s
                    ),
                ));
            }
            states.push(r);
        }
        if !(length_m > 0.0 && width_m > 0.0) {
            return Err(invalid(
                path,
                o.line,
                element,
                format!("its shape must have a positive size ({length_m} m × {width_m} m)"),
            ));
        }
        vehicles.push(RecordedVehicle {
            name: format!("cr-{}", o.id),
            length_m,
            width_m,
            states,
        });
    }
    Ok(RecordedTraffic { mode, vehicles })
}

/// The ego of a planning problem (module doc) on `lanes`.
pub fn ego_of(
    path: &Path,
    cr: &model::Scenario,
    pp: &model::PlanningProblem,
    lanes: &LaneRoad,
) -> Result<VehicleSpec, ScenarioError> {
    let element = format!("planningProblem {}", pp.id);
    let init = &pp.initial_state;
    let state = init.replay(cr.time_step_s).ok_or_else(|| {
        invalid(
            path,
            init.line,
            element.clone(),
            "its initial state needs a time, a position, an orientation and a velocity".into(),
        )
    })?;
    let Some((lane, s_m, d_m)) = lane_at(lanes, state.position_m, state.orientation_rad) else {
        return Err(invalid(
            path,
            init.line,
            element,
            format!(
                "its initial state at ({}, {}) m is on no lanelet",
                state.position_m[0], state.position_m[1]
            ),
        ));
    };
    let goal = goal_of(pp, cr.time_step_s, state.time_s);
    let route = if goal.has_position() {
        let mut best: Option<Vec<LaneId>> = None;
        let mut unreachable = None;
        for g in &goal.states {
            let Some(position) = &g.position else {
                continue;
            };
            let targets = goal_lanes(position, lanes);
            match sim::route::shortest_route(lanes, lane, &targets) {
                Some(r) => {
                    let length = |r: &[LaneId]| -> f64 {
                        r.iter()
                            .filter_map(|id| lanes.lane(*id))
                            .map(|l| l.length_m())
                            .sum()
                    };
                    if best.as_ref().is_none_or(|b| length(&r) < length(b)) {
                        best = Some(r);
                    }
                }
                None => unreachable = Some((g.source.clone(), targets)),
            }
        }
        if best.is_none() {
            let (source, targets) = unreachable.unwrap_or_default();
            let line = source
                .rsplit(' ')
                .next()
                .and_then(|l| l.parse().ok())
                .unwrap_or(pp.line);
            let message = if targets.is_empty() {
                format!(
                    "the goal ({source}) lies on no lanelet: no route from lanelet {lane}, where \
                     the ego starts, can reach it"
                )
            } else {
                format!(
                    "no route along the lanelets (successors and same-direction neighbours) \
                     leads from lanelet {lane}, where the ego starts, to its goal ({source}, on \
                     lanelets [{}])",
                    targets
                        .iter()
                        .map(|l| l.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
            return Err(invalid(path, line, element, message));
        }
        best
    } else {
        None
    };
    let speed_limit_mps = route
        .as_deref()
        .unwrap_or(std::slice::from_ref(&lane))
        .iter()
        .find_map(|id| cr.lanelet(i64::from(id.0))?.speed_limit_mps);
    let target_speed_mps = goal
        .velocity_midpoint_mps()
        .or(speed_limit_mps)
        .unwrap_or(state.velocity_mps);
    Ok(VehicleSpec {
        name: "ego".into(),
        preset: EGO_PRESET.into(),
        vehicle_model: None,
        lane: StartLane::Id(lane),
        x_m: s_m,
        y_offset_m: d_m,
        speed_mps: state.velocity_mps,
        target_speed_mps,
        driver: Driver::planner(EGO_PLANNER),
        connected: true,
        goal: Some(goal),
        route,
    })
}

impl Scenario {
    /// A CommonRoad file as a scenario (module doc), its obstacles in `mode`; checked like a
    /// scenario TOML. Refusals name the file, the line and the element.
    pub fn from_commonroad(path: &Path, mode: TrafficMode) -> Result<Self, ScenarioError> {
        let file = absolute(path);
        let (cr, lanes) = mergesim_commonroad::read_with_road(path)?;
        let origin = path.display().to_string();
        let Some(pp) = cr.planning_problems.first() else {
            return Err(ScenarioError::Invalid {
                origin,
                line: Line(None),
                field: Some("planningProblem".into()),
                message: "the file has no planning problem: nothing to drive (a scenario TOML \
                          with [sim.road] commonroad = … places its own vehicles on its road)"
                    .into(),
            });
        };
        let t0_s = pp
            .initial_state
            .time_step
            .map_or(0.0, |t| t.midpoint() * cr.time_step_s);
        let ego = ego_of(path, &cr, pp, &lanes)?;
        let traffic = recorded_traffic(path, &cr, mode, t0_s)?;
        let last_state_s = traffic
            .vehicles
            .iter()
            .filter_map(|v| v.states.last().map(|s| s.time_s))
            .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))));
        let defaults = SimConfig::default();
        let duration_s = ego
            .goal
            .as_ref()
            .and_then(Goal::time_end_s)
            .or(last_state_s)
            .filter(|d| *d > 0.0)
            .unwrap_or(defaults.duration_s);
        let name = if cr.benchmark_id.is_empty() {
            path.file_stem()
                .map_or_else(|| "commonroad".into(), |s| s.to_string_lossy().into_owned())
        } else {
            cr.benchmark_id.clone()
        };
        let route = match &ego.route {
            Some(r) => format!(
                ", route along lanelets {}",
                r.iter()
                    .map(|l| l.to_string())
                    .collect::<Vec<_>>()
                    .join(" → ")
            ),
            None => String::new(),
        };
        let mut scenario = Scenario {
            description: format!(
                "CommonRoad {name}: {} lanelets, {} recorded vehicles ({mode}), the ego of \
                 planning problem {} on lanelet {}{route}",
                cr.lanelets.len(),
                traffic.vehicles.len(),
                pp.id,
                ego.lane
            ),
            name,
            params: planner::ParameterSet::default(),
            sim: SimConfig {
                lane_road: Some(LaneRoadConfig {
                    commonroad: Some(CommonRoadRoad::of(file, mode, &cr)),
                    ..LaneRoadConfig::default()
                }),
                duration_s,
                recorded_traffic: traffic,
                ..defaults
            },
            vehicles: vec![ego],
            traffic: crate::traffic::Traffic::new(),
            generated_vehicles: 0,
            randomise: crate::randomisation::Randomisation::default(),
            planner_overrides: toml::Table::new(),
            source: None,
        };
        scenario.apply_parameter_set(&origin, None)?;
        scenario.check(&origin, None)?;
        Ok(scenario)
    }

    /// The same scenario with its recorded traffic in `mode`; refused for a scenario whose
    /// road is not a CommonRoad file's.
    pub fn with_recorded_traffic(&self, mode: TrafficMode) -> Result<Self, ScenarioError> {
        let mut scenario = self.clone();
        let Some(road) = scenario
            .sim
            .lane_road
            .as_mut()
            .and_then(|c| c.commonroad.as_mut())
        else {
            return Err(ScenarioError::Invalid {
                origin: self.name.clone(),
                line: Line(None),
                field: Some("recorded_traffic".into()),
                message: "--recorded-traffic applies to a scenario on a CommonRoad road (an \
                          .xml file, or [sim.road] commonroad = …)"
                    .into(),
            });
        };
        road.recorded_traffic = mode;
        scenario.sim.recorded_traffic.mode = mode;
        Ok(scenario)
    }

    /// The same scenario lasting `duration_s`, checked again.
    pub fn with_duration(&self, duration_s: f64) -> Result<Self, ScenarioError> {
        let mut scenario = self.clone();
        scenario.sim.duration_s = duration_s;
        scenario.check(&format!("{} with --duration {duration_s}", self.name), None)?;
        Ok(scenario)
    }
}
