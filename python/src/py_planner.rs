//! Planners written in Python (`mergesim.register_planner`): a process-wide table of Python
//! factories by name, and the `Behaviour` that runs one of them for one vehicle.
//!
//! - **The table** holds, under each name, a callable (usually a class) that returns a planner:
//!   an object with `plan(observation) -> decision`. A name must be free: not a built-in
//!   planner, not the environment's `external`, not registered already.
//! - **The registry** of a call (`run`, `sweep`, `study`, `MergeEnv`) is the built-in one plus
//!   the table as it is when the call starts ([`registry`]).
//! - **One planner object per vehicle**: the factory is called (`factory()`) when the world is
//!   built; at every planning cycle of the vehicle the adapter takes the GIL (the runs go on
//!   worker threads without it), converts the `Observation` into a dict (python/README.md,
//!   "Planners in Python"), calls `plan`, and converts and checks the result. A Python
//!   exception or a bad decision becomes a `BehaviourError` with the Python message: the run
//!   fails (a sweep row `failed`), the process does not.
//!
//! A vehicle's planner sees only its own observations, so a sweep's rows are the same whatever
//! the thread count, as long as `plan` depends only on its object and its observation.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};

use mergesim_types::{
    Behaviour, BehaviourError, Decision, FallbackReason, Observation, PathPoint, VehicleShape,
    VehicleState,
};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};
use sim::SimError;
use sim::registry::{BehaviourRegistry, FactoryInput};

use crate::errors::BindingError;
use crate::external::EXTERNAL_PLANNER;
use crate::road::Road;

/// Python planner factories by name (module doc). Only touched with the GIL held, and never
/// held while taking the GIL.
static PLANNERS: Mutex<BTreeMap<String, Arc<Py<PyAny>>>> = Mutex::new(BTreeMap::new());

fn table() -> std::sync::MutexGuard<'static, BTreeMap<String, Arc<Py<PyAny>>>> {
    PLANNERS.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The built-in planners plus the Python planners registered now.
pub(crate) fn registry() -> Result<BehaviourRegistry, BindingError> {
    let mut registry = BehaviourRegistry::builtin();
    for (name, factory) in table().iter() {
        registry
            .register(name, python_factory(name, factory.clone()))
            .map_err(|e| BindingError::input(&e))?;
    }
    Ok(registry)
}

/// Registers `factory` under `name` (module doc); refuses a bad or taken name.
#[pyfunction]
pub(crate) fn register_planner(name: &str, factory: Bound<'_, PyAny>) -> PyResult<()> {
    if !factory.is_callable() {
        return Err(BindingError::Input(format!(
            "planner {name:?}: the factory must be callable (a class whose instances have \
             plan(observation)), got {}",
            factory.get_type().name()?
        ))
        .into());
    }
    let mut table = table();
    // The registry's own checks (name syntax, taken), with the built-ins, the environment's
    // `external` and the Python planners already there.
    let mut taken = BehaviourRegistry::builtin();
    let dummy: sim::registry::BehaviourFactory = Arc::new(|input: &FactoryInput<'_>| {
        Err(SimError::InvalidScenario(input.spec.name.clone()))
    });
    for existing in table.keys().map(String::as_str).chain([EXTERNAL_PLANNER]) {
        taken
            .register(existing, dummy.clone())
            .map_err(|e| BindingError::input(&e))?;
    }
    taken
        .register(name, dummy)
        .map_err(|e| BindingError::input(&e))?;
    table.insert(name.to_string(), Arc::new(factory.unbind()));
    Ok(())
}

/// Removes the Python planner `name` (runs already started keep it).
#[pyfunction]
pub(crate) fn unregister_planner(name: &str) -> PyResult<()> {
    match table().remove(name) {
        Some(_) => Ok(()),
        None => Err(BindingError::Input(format!(
            "planner {name:?}: not a registered Python planner"
        ))
        .into()),
    }
}

/// The names of the Python planners, sorted.
#[pyfunction]
pub(crate) fn python_planners() -> Vec<String> {
    table().keys().cloned().collect()
}

/// The registry factory of the Python planner `name`.
fn python_factory(name: &str, factory: Arc<Py<PyAny>>) -> sim::registry::BehaviourFactory {
    let name = name.to_string();
    Arc::new(move |input: &FactoryInput<'_>| {
        Python::attach(|py| {
            let planner = factory.bind(py).call0().map_err(|e| SimError::Behaviour {
                vehicle: input.spec.name.clone(),
                source: format!(
                    "Python planner '{name}': creating it failed: {}",
                    python_message(py, &e)
                )
                .into(),
            })?;
            let road = Py::new(py, Road::new(Arc::clone(input.lanes))).map_err(|e| {
                SimError::Behaviour {
                    vehicle: input.spec.name.clone(),
                    source: python_message(py, &e).into(),
                }
            })?;
            Ok(Box::new(PythonPlanner {
                name: name.clone(),
                vehicle: input.spec.name.clone(),
                planner: planner.unbind(),
                road,
            }) as Box<dyn Behaviour>)
        })
    })
}

/// One vehicle's Python planner (module doc).
pub(crate) struct PythonPlanner {
    /// The registered name.
    name: String,
    /// The vehicle's name (`observation["ego_name"]`).
    vehicle: String,
    /// The object whose `plan` is called.
    planner: Py<PyAny>,
    /// The run's road (`observation["road"]`).
    road: Py<Road>,
}

impl Behaviour for PythonPlanner {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        Python::attach(|py| {
            let observation = observation(py, obs, &self.vehicle, &self.road)
                .map_err(|e| self.error(python_message(py, &e)))?;
            let decided = self
                .planner
                .bind(py)
                .call_method1(intern!(py, "plan"), (observation,))
                .map_err(|e| self.error(python_message(py, &e)))?;
            decision(&decided, obs).map_err(|e| self.error(e))
        })
    }
}

impl PythonPlanner {
    fn error(&self, message: String) -> BehaviourError {
        format!("Python planner '{}': {message}", self.name).into()
    }
}

/// `error` as Python prints its last line (`ValueError: ...`), with where it was raised.
fn python_message(py: Python<'_>, error: &PyErr) -> String {
    let mut text = error.to_string();
    if let Some(traceback) = error.traceback(py)
        && let Ok(formatted) = traceback.format()
        && let Some(place) = formatted
            .lines()
            .rev()
            .find(|l| l.trim_start().starts_with("File "))
    {
        text.push_str(&format!(" ({})", place.trim()));
    }
    text
}

fn state<'py>(py: Python<'py>, s: &VehicleState) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(intern!(py, "x_m"), s.x_m)?;
    d.set_item(intern!(py, "y_m"), s.y_m)?;
    d.set_item(intern!(py, "yaw_rad"), s.yaw_rad)?;
    d.set_item(intern!(py, "speed_mps"), s.speed_mps)?;
    Ok(d)
}

fn shape<'py>(py: Python<'py>, s: &VehicleShape) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(intern!(py, "length_m"), s.length_m)?;
    d.set_item(intern!(py, "width_m"), s.width_m)?;
    d.set_item(intern!(py, "wheelbase_m"), s.wheelbase_m)?;
    d.set_item(intern!(py, "max_brake_decel_mps2"), s.max_brake_decel_mps2)?;
    Ok(d)
}

/// The observation as a dict (python/README.md, "Planners in Python").
fn observation<'py>(
    py: Python<'py>,
    obs: &Observation<'_>,
    vehicle: &str,
    road: &Py<Road>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(intern!(py, "time_s"), obs.time_s)?;
    d.set_item(intern!(py, "ego_id"), obs.ego_id)?;
    d.set_item(intern!(py, "ego_name"), PyString::new(py, vehicle))?;
    d.set_item(intern!(py, "ego"), state(py, &obs.ego)?)?;
    d.set_item(intern!(py, "ego_shape"), shape(py, &obs.ego_shape)?)?;
    d.set_item(intern!(py, "target_speed_mps"), obs.target_speed_mps)?;
    d.set_item(intern!(py, "mu"), obs.mu)?;
    // Where the ego is on the road: its nearest lane and its (s, d) there.
    let hit = obs.lanes.nearest_lane([obs.ego.x_m, obs.ego.y_m]);
    let lane = PyDict::new(py);
    lane.set_item(intern!(py, "id"), hit.lane.0)?;
    lane.set_item(intern!(py, "s_m"), hit.frame.s_m)?;
    lane.set_item(intern!(py, "d_m"), hit.frame.d_m)?;
    lane.set_item(
        intern!(py, "width_m"),
        obs.lanes
            .lane(hit.lane)
            .map_or(f64::NAN, |l| l.width_m(hit.frame.s_m)),
    )?;
    d.set_item(intern!(py, "lane"), lane)?;
    let neighbours = PyList::empty(py);
    for n in obs.neighbours {
        let item = PyDict::new(py);
        item.set_item(intern!(py, "id"), n.id)?;
        item.set_item(intern!(py, "state"), state(py, &n.state)?)?;
        item.set_item(intern!(py, "shape"), shape(py, &n.shape)?)?;
        neighbours.append(item)?;
    }
    d.set_item(intern!(py, "neighbours"), neighbours)?;
    let shared = PyList::empty(py);
    for message in obs.shared_paths {
        let item = PyDict::new(py);
        item.set_item(intern!(py, "sender"), message.vehicle_id)?;
        item.set_item(intern!(py, "stamp_s"), message.stamp_s)?;
        item.set_item(intern!(py, "speed_mps"), message.speed_mps)?;
        let points = PyList::empty(py);
        for w in &message.waypoints {
            points.append(PyTuple::new(py, [w.t_s, w.x_m, w.y_m])?)?;
        }
        item.set_item(intern!(py, "points"), points)?;
        shared.append(item)?;
    }
    d.set_item(intern!(py, "shared_paths"), shared)?;
    d.set_item(intern!(py, "road"), road.clone_ref(py))?;
    Ok(d)
}

/// Most points of one decided path.
const MAX_PATH_POINTS: usize = 100_000;

/// A path point: a dict with x_m, y_m, speed_mps, t_s, or a sequence of those four numbers.
fn path_point(value: &Bound<'_, PyAny>, index: usize) -> Result<PathPoint, String> {
    let [x_m, y_m, speed_mps, t_s] = if let Ok(d) = value.cast::<PyDict>() {
        let mut out = [0.0; 4];
        for (slot, key) in out.iter_mut().zip(["x_m", "y_m", "speed_mps", "t_s"]) {
            let item = d
                .get_item(key)
                .map_err(|e| e.to_string())?
                .ok_or_else(|| format!("path[{index}]: no key {key:?}"))?;
            *slot = item
                .extract::<f64>()
                .map_err(|_| format!("path[{index}].{key}: not a number"))?;
        }
        out
    } else {
        let numbers: Vec<f64> = value.extract().map_err(|_| {
            format!(
                "path[{index}]: need a dict (x_m, y_m, speed_mps, t_s) or 4 numbers, got {}",
                value
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            )
        })?;
        <[f64; 4]>::try_from(numbers.as_slice()).map_err(|_| {
            format!(
                "path[{index}]: need 4 numbers (x_m, y_m, speed_mps, t_s), got {}",
                numbers.len()
            )
        })?
    };
    for (value, key) in
        [x_m, y_m, speed_mps, t_s]
            .into_iter()
            .zip(["x_m", "y_m", "speed_mps", "t_s"])
    {
        if !value.is_finite() {
            return Err(format!("path[{index}].{key} = {value}: not finite"));
        }
    }
    if speed_mps < 0.0 {
        return Err(format!(
            "path[{index}].speed_mps = {speed_mps}: must be ≥ 0"
        ));
    }
    Ok(PathPoint {
        x_m,
        y_m,
        speed_mps,
        t_s,
    })
}

/// The `Decision` of what `plan` returned: a dict {"path": [...], "broadcast": bool = True,
/// "fallback": str | None = None}, or the path alone. The path must be non-empty, finite, with
/// speeds ≥ 0 and strictly increasing times.
fn decision(value: &Bound<'_, PyAny>, obs: &Observation<'_>) -> Result<Decision, String> {
    let py = value.py();
    let (path_value, broadcast, fallback) = if let Ok(d) = value.cast::<PyDict>() {
        let path = d
            .get_item(intern!(py, "path"))
            .map_err(|e| e.to_string())?
            .ok_or("the decision dict has no \"path\"")?;
        let broadcast = match d
            .get_item(intern!(py, "broadcast"))
            .map_err(|e| e.to_string())?
        {
            None => true,
            Some(b) => b
                .extract::<bool>()
                .map_err(|_| "decision[\"broadcast\"]: must be True or False".to_string())?,
        };
        let fallback = match d
            .get_item(intern!(py, "fallback"))
            .map_err(|e| e.to_string())?
        {
            None => None,
            Some(f) if f.is_none() => None,
            Some(f) => Some(FallbackReason::Other(f.extract::<String>().map_err(
                |_| "decision[\"fallback\"]: must be a string or None".to_string(),
            )?)),
        };
        (path, broadcast, fallback)
    } else {
        (value.clone(), true, None)
    };
    if path_value.is_none() {
        return Err("plan() returned None: return a path or {\"path\": ...}".into());
    }
    let points = path_value.try_iter().map_err(|_| {
        format!(
            "the path must be a sequence of points, got {}",
            path_value
                .get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        )
    })?;
    let mut path: Vec<PathPoint> = Vec::new();
    for (index, point) in points.enumerate() {
        if index >= MAX_PATH_POINTS {
            return Err(format!("the path has more than {MAX_PATH_POINTS} points"));
        }
        let point = path_point(&point.map_err(|e| e.to_string())?, index)?;
        if let Some(last) = path.last()
            && point.t_s <= last.t_s
        {
            return Err(format!(
                "path[{index}].t_s = {}: not after path[{}].t_s = {} (times must increase)",
                point.t_s,
                index - 1,
                last.t_s
            ));
        }
        path.push(point);
    }
    if path.is_empty() {
        return Err("the path is empty".into());
    }
    let decision = if broadcast {
        Decision::follow_and_share(path, obs)
    } else {
        Decision::follow(path)
    };
    Ok(Decision {
        fallback,
        ..decision
    })
}
