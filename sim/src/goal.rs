//! A vehicle's goal, with CommonRoad's meaning (a planning problem's `goalState`s): the goal is
//! reached at the first instant at which the vehicle meets every condition of one goal state:
//! its position in one of the state's shapes or lanes, its heading in the orientation
//! interval, its speed in the velocity interval and the time in the time interval. A condition
//! the state does not give always holds (a goal state with only a time interval, like the A9
//! test file's, is reached as soon as the time enters it).
//!
//! The world checks goals at every log period (`log_period_s`), after the physics step, on the
//! vehicle's centre of gravity (`crate::world`); the first instant found is the goal time.
//! Intervals include their ends.

use mergesim_types::VehicleState;
use mergesim_types::lanes::{LaneId, LaneRoad};
use serde::{Deserialize, Serialize};

/// A closed interval `[start, end]` (units of the field holding it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Interval {
    /// Lower end (included).
    pub start: f64,
    /// Upper end (included).
    pub end: f64,
}

impl Interval {
    /// Whether `v` lies in the interval, ends included.
    pub(crate) fn contains(&self, v: f64) -> bool {
        self.start <= v && v <= self.end
    }

    /// The interval's midpoint.
    pub fn midpoint(&self) -> f64 {
        0.5 * (self.start + self.end)
    }

    /// Whether the angle `a_rad` lies in the interval of angles: `a` shifted by a whole number
    /// of turns into `[start, start + 2π)` is at most `end` (so an interval crossing ±π works).
    pub(crate) fn contains_angle(&self, a_rad: f64) -> bool {
        let turn = std::f64::consts::TAU;
        if self.end - self.start >= turn {
            return true;
        }
        let shifted = self.start + (a_rad - self.start).rem_euclid(turn);
        shifted <= self.end
    }
}

/// A goal region shape (file coordinates, m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GoalShape {
    /// A rectangle of `length_m` along `orientation_rad`, `width_m` across, centred on
    /// `center_m`.
    Rectangle {
        /// Extent along the orientation (m).
        length_m: f64,
        /// Extent across it (m).
        width_m: f64,
        /// Rotation (rad, counter-clockwise from +x).
        orientation_rad: f64,
        /// Centre (m).
        center_m: [f64; 2],
    },
    /// A circle.
    Circle {
        /// Radius (m).
        radius_m: f64,
        /// Centre (m).
        center_m: [f64; 2],
    },
    /// A simple polygon (its vertices in order, m).
    Polygon {
        /// Vertices (m).
        vertices_m: Vec<[f64; 2]>,
    },
}

impl GoalShape {
    /// Whether the point lies in the shape (boundary included).
    pub fn contains(&self, p_m: [f64; 2]) -> bool {
        match self {
            GoalShape::Rectangle {
                length_m,
                width_m,
                orientation_rad,
                center_m,
            } => {
                let (s, c) = orientation_rad.sin_cos();
                let (dx, dy) = (p_m[0] - center_m[0], p_m[1] - center_m[1]);
                let along = dx * c + dy * s;
                let across = -dx * s + dy * c;
                along.abs() <= 0.5 * length_m && across.abs() <= 0.5 * width_m
            }
            GoalShape::Circle { radius_m, center_m } => {
                (p_m[0] - center_m[0]).hypot(p_m[1] - center_m[1]) <= *radius_m
            }
            GoalShape::Polygon { vertices_m } => polygon_contains(vertices_m, p_m),
        }
    }

    /// A point inside the shape (a rectangle's or circle's centre, a polygon's vertex mean).
    pub fn center_m(&self) -> [f64; 2] {
        match self {
            GoalShape::Rectangle { center_m, .. } | GoalShape::Circle { center_m, .. } => *center_m,
            GoalShape::Polygon { vertices_m } => {
                let n = vertices_m.len().max(1) as f64;
                [
                    vertices_m.iter().map(|p| p[0]).sum::<f64>() / n,
                    vertices_m.iter().map(|p| p[1]).sum::<f64>() / n,
                ]
            }
        }
    }
}

/// Even–odd rule, with points on an edge counted inside.
fn polygon_contains(vertices: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = vertices.len();
    if n < 3 {
        return false;
    }
    let mut inside = false;
    for i in 0..n {
        let a = vertices[i];
        let b = vertices[(i + 1) % n];
        // On the edge (within 1e-9 m).
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        if len2 > 0.0 {
            let t = (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2).clamp(0.0, 1.0);
            let (qx, qy) = (a[0] + t * ex, a[1] + t * ey);
            if (p[0] - qx).hypot(p[1] - qy) <= 1e-9 {
                return true;
            }
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Where a goal state's vehicle must be.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GoalPosition {
    /// In any of these shapes.
    Shapes(Vec<GoalShape>),
    /// On any of these lanes (CommonRoad lanelets): the centre of gravity inside the lane.
    Lanes(Vec<LaneId>),
}

impl GoalPosition {
    /// Whether the point meets the position condition.
    pub(crate) fn contains(&self, p_m: [f64; 2], lanes: &LaneRoad) -> bool {
        match self {
            GoalPosition::Shapes(shapes) => shapes.iter().any(|s| s.contains(p_m)),
            GoalPosition::Lanes(ids) => ids
                .iter()
                .any(|id| lanes.lane(*id).is_some_and(|l| l.contains(p_m))),
        }
    }
}

/// One goal state: every condition given must hold at one instant.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GoalState {
    /// Time since the start of the run (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<Interval>,
    /// Position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<GoalPosition>,
    /// Heading (rad), compared modulo a turn (`Interval::contains_angle`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_rad: Option<Interval>,
    /// Speed (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_mps: Option<Interval>,
    /// Where it comes from (e.g. `goalState on line 812`), for messages.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub source: String,
}

impl GoalState {
    /// Whether the vehicle in `state` (its centre of gravity) at time `t_s` (since the start
    /// of the run, s) meets every condition of this goal state.
    pub fn is_met(&self, t_s: f64, state: &VehicleState, lanes: &LaneRoad) -> bool {
        self.time_s.is_none_or(|i| i.contains(t_s))
            && self
                .velocity_mps
                .is_none_or(|i| i.contains(state.speed_mps))
            && self
                .orientation_rad
                .is_none_or(|i| i.contains_angle(state.yaw_rad))
            && self
                .position
                .as_ref()
                .is_none_or(|p| p.contains([state.x_m, state.y_m], lanes))
    }
}

/// A vehicle's goal: reached when any one of its states is met (module doc).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Goal {
    /// The goal states.
    pub states: Vec<GoalState>,
}

impl Goal {
    /// Whether the vehicle in `state` at time `t_s` (s) meets one of the goal states.
    pub fn is_reached(&self, t_s: f64, state: &VehicleState, lanes: &LaneRoad) -> bool {
        self.states.iter().any(|s| s.is_met(t_s, state, lanes))
    }

    /// The latest end of the goal states' time intervals (s), if every state has one (the
    /// run need not last beyond it).
    pub fn time_end_s(&self) -> Option<f64> {
        let mut end: Option<f64> = None;
        for s in &self.states {
            let e = s.time_s?.end;
            end = Some(end.map_or(e, |x| x.max(e)));
        }
        end
    }

    /// The midpoint of the goal states' velocity intervals (the first state that gives one).
    pub fn velocity_midpoint_mps(&self) -> Option<f64> {
        self.states
            .iter()
            .find_map(|s| s.velocity_mps.map(|i| i.midpoint()))
    }

    /// Whether any goal state constrains the position (then the vehicle routes to it).
    pub fn has_position(&self) -> bool {
        self.states.iter().any(|s| s.position.is_some())
    }
}

/// A vehicle's goal at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GoalOutcome {
    /// The vehicle's name.
    pub vehicle: String,
    /// Whether it reached its goal.
    pub reached: bool,
    /// The first instant it was found in its goal (s), if it was.
    pub time_s: Option<f64>,
}

#[cfg(test)]
#[path = "goal_tests.rs"]
mod tests;
