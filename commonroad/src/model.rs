//! The typed content of a CommonRoad file, in the file's own coordinates and units (SI,
//! radians). Serialised as the JSON of `merge_sim commonroad dump`.

use serde::Serialize;

/// The format version of the file (`commonRoadVersion`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum FormatVersion {
    /// 2018b: obstacles are `<obstacle>` with a `<role>` (static/dynamic), no `laneletType`.
    #[serde(rename = "2018b")]
    V2018b,
    /// 2020a: `<dynamicObstacle>` / `<staticObstacle>`, `laneletType`, traffic signs.
    #[serde(rename = "2020a")]
    V2020a,
}

/// A value given exactly or as an interval `[start, end]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Value {
    /// `<exact>`.
    Exact(f64),
    /// `<intervalStart>`, `<intervalEnd>`.
    Interval {
        /// Lower end.
        start: f64,
        /// Upper end.
        end: f64,
    },
}

impl Value {
    /// The value replayed: the exact value, or the interval's midpoint.
    pub fn midpoint(&self) -> f64 {
        match *self {
            Value::Exact(v) => v,
            Value::Interval { start, end } => 0.5 * (start + end),
        }
    }

    /// Whether `v` is the exact value or lies in the interval (ends included).
    pub fn contains(&self, v: f64) -> bool {
        match *self {
            Value::Exact(x) => v == x,
            Value::Interval { start, end } => start <= v && v <= end,
        }
    }
}

/// A planar shape; rectangles and circles are centred on `center_m` (the state's position for an
/// obstacle shape, where the file gives no centre).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A rectangle: `length_m` along `orientation_rad`, `width_m` across it.
    Rectangle {
        /// Extent along the orientation (m).
        length_m: f64,
        /// Extent across it (m).
        width_m: f64,
        /// Rotation (rad, counter-clockwise from +x); 0 if the file gives none.
        orientation_rad: f64,
        /// Centre (m); the origin if the file gives none.
        center_m: [f64; 2],
    },
    /// A circle.
    Circle {
        /// Radius (m).
        radius_m: f64,
        /// Centre (m); the origin if the file gives none.
        center_m: [f64; 2],
    },
    /// A polygon (its vertices, m).
    Polygon {
        /// Vertices (m).
        vertices_m: Vec<[f64; 2]>,
    },
}

impl Shape {
    /// The shape's centre: a rectangle's or circle's centre, a polygon's vertex mean.
    pub fn center_m(&self) -> [f64; 2] {
        match self {
            Shape::Rectangle { center_m, .. } | Shape::Circle { center_m, .. } => *center_m,
            Shape::Polygon { vertices_m } => {
                let n = vertices_m.len().max(1) as f64;
                let sx: f64 = vertices_m.iter().map(|p| p[0]).sum();
                let sy: f64 = vertices_m.iter().map(|p| p[1]).sum();
                [sx / n, sy / n]
            }
        }
    }
}

/// A state's position.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Position {
    /// An exact point (m).
    Point([f64; 2]),
    /// An uncertain position or a goal region: a union of shapes.
    Shapes(Vec<Shape>),
    /// A goal region given as lanelets.
    Lanelets(Vec<i64>),
}

impl Position {
    /// The position replayed: the point, or the first shape's centre; `None` for lanelets.
    pub fn replay_m(&self) -> Option<[f64; 2]> {
        match self {
            Position::Point(p) => Some(*p),
            Position::Shapes(shapes) => shapes.first().map(Shape::center_m),
            Position::Lanelets(_) => None,
        }
    }
}

/// One state of an obstacle or a planning problem. Absent fields are `None`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct State {
    /// Line of the `<state>`/`<initialState>`/`<goalState>` element.
    pub line: u32,
    /// Time step (`<time>`): multiply by the file's `timeStepSize` for seconds.
    pub time_step: Option<Value>,
    /// Position.
    pub position: Option<Position>,
    /// Orientation (rad).
    pub orientation_rad: Option<Value>,
    /// Speed (m/s).
    pub velocity_mps: Option<Value>,
    /// Acceleration (m/s²).
    pub acceleration_mps2: Option<Value>,
    /// Yaw rate (rad/s).
    pub yaw_rate_radps: Option<Value>,
    /// Slip angle (rad).
    pub slip_angle_rad: Option<Value>,
}

/// A state in replay form: exact values, intervals replaced by their midpoints, position
/// rectangles by their centres, time in seconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReplayState {
    /// Time (s) = time step × `timeStepSize`.
    pub time_s: f64,
    /// Position (m).
    pub position_m: [f64; 2],
    /// Orientation (rad).
    pub orientation_rad: f64,
    /// Speed (m/s).
    pub velocity_mps: f64,
}

impl State {
    /// This state in replay form, given the file's time step; `None` if it lacks a time, a
    /// point-like position, an orientation or a velocity.
    pub fn replay(&self, time_step_s: f64) -> Option<ReplayState> {
        Some(ReplayState {
            time_s: self.time_step?.midpoint() * time_step_s,
            position_m: self.position.as_ref()?.replay_m()?,
            orientation_rad: self.orientation_rad?.midpoint(),
            velocity_mps: self.velocity_mps?.midpoint(),
        })
    }
}

/// How a lanelet's neighbour is driven relative to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DrivingDir {
    /// Same direction.
    Same,
    /// Opposite direction.
    Opposite,
}

/// A lanelet's left or right neighbour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Adjacent {
    /// The neighbour's id.
    pub id: i64,
    /// Its driving direction relative to this lanelet.
    pub driving_dir: DrivingDir,
}

/// One lanelet.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Lanelet {
    /// Its id.
    pub id: i64,
    /// Line of its `<lanelet>` element.
    pub line: u32,
    /// Left bound vertices (m), in the driving direction.
    pub left_bound_m: Vec<[f64; 2]>,
    /// Right bound vertices (m), as many as the left bound's.
    pub right_bound_m: Vec<[f64; 2]>,
    /// Predecessor ids.
    pub predecessors: Vec<i64>,
    /// Successor ids.
    pub successors: Vec<i64>,
    /// Left neighbour.
    pub adjacent_left: Option<Adjacent>,
    /// Right neighbour.
    pub adjacent_right: Option<Adjacent>,
    /// `laneletType` values (2020a; empty in 2018b).
    pub lanelet_types: Vec<String>,
    /// Speed limit (m/s): 2018b's `<speedLimit>`, or a 2020a traffic sign `274` (max speed)
    /// referenced by the lanelet.
    pub speed_limit_mps: Option<f64>,
}

/// An obstacle (dynamic or static).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Obstacle {
    /// Its id.
    pub id: i64,
    /// Line of its element.
    pub line: u32,
    /// `<type>` (car, truck, parkedVehicle, ...).
    pub obstacle_type: String,
    /// Its shape, centred on the origin and unrotated (placed on each state's position and
    /// orientation).
    pub shape: Shape,
    /// The initial state.
    pub initial_state: State,
    /// The trajectory's states (empty for a static obstacle).
    pub trajectory: Vec<State>,
}

/// A planning problem.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanningProblem {
    /// Its id.
    pub id: i64,
    /// Line of its element.
    pub line: u32,
    /// The ego's initial state.
    pub initial_state: State,
    /// Goal states: reaching any one of them is reaching the goal.
    pub goal_states: Vec<State>,
}

/// A whole CommonRoad file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scenario {
    /// `commonRoadVersion`.
    pub format: FormatVersion,
    /// `benchmarkID` (empty if absent).
    pub benchmark_id: String,
    /// `timeStepSize` (s).
    pub time_step_s: f64,
    /// The lanelet network.
    pub lanelets: Vec<Lanelet>,
    /// Dynamic obstacles.
    pub dynamic_obstacles: Vec<Obstacle>,
    /// Static obstacles.
    pub static_obstacles: Vec<Obstacle>,
    /// Planning problems.
    pub planning_problems: Vec<PlanningProblem>,
}

impl Scenario {
    /// The lanelet with this id.
    pub fn lanelet(&self, id: i64) -> Option<&Lanelet> {
        self.lanelets.iter().find(|l| l.id == id)
    }
}
