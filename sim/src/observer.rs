//! Observers of the tick: what is measured and recorded of a run, kept out of the tick loop.
//!
//! The [`crate::World`] advances the physics and the vehicles' decisions; at every planning cycle
//! of a vehicle, at every logged instant (the log period, 20 Hz by default) and for every event
//! it calls its observers in a fixed order: the per-vehicle metrics and time series
//! ([`crate::run_log::RunLog`]), the Rerun recording ([`crate::recording_observer`]), then any
//! observer a user added with [`crate::World::add_observer`].

use std::time::Duration;

use mergesim_types::{Decision, GridSpec, Observation, PathPoint, SharedLocalPath, VehicleId};
use vehicles::Kinematics;

use crate::error::SimError;
use crate::event::SimEvent;
use crate::outcome::TimeSeriesRow;
use crate::profile::Phase;
use crate::safety::BodyState;

/// One vehicle at a logged instant.
#[derive(Clone, Copy, Debug)]
pub struct VehicleView<'a> {
    /// Its id (index in the scenario).
    pub id: VehicleId,
    /// Its kinematic state.
    pub kinematics: &'a Kinematics,
    /// Its chassis box, as the safety checks see it.
    pub body: &'a BodyState,
    /// Its row of the time series: its name, the motion state the metrics see and the speed
    /// its plan asks for now.
    pub sample: &'a TimeSeriesRow,
    /// The path it is tracking.
    pub path: &'a [PathPoint],
    /// Whether it is connected (sends and receives shared paths).
    pub connected: bool,
    /// The fresh shared paths it holds (empty unless an observer asked for them).
    pub received: &'a [SharedLocalPath],
}

/// One vehicle's planning cycle.
pub struct PlanView<'a, 'o> {
    /// The vehicle's name.
    pub name: &'a str,
    /// What it observed.
    pub observation: &'a Observation<'o>,
    /// What it decided.
    pub decision: &'a Decision,
    /// Samples its potential field on a grid (`None` if it has none).
    pub field: &'a dyn Fn(&GridSpec) -> Option<Vec<f64>>,
    /// Whether the field-logging period has come.
    pub field_due: bool,
    /// Wall time of its `plan` call (µs); not reproducible.
    pub plan_time_us: f64,
    /// How its optimiser ended this cycle, if it reports one
    /// (`Behaviour::optimiser_report`).
    pub optimiser: Option<mergesim_types::OptimiserReport>,
}

/// Something that watches a run (module doc). Every method defaults to doing nothing.
pub trait TickObserver: Send {
    /// Whether [`VehicleView::received`] should be filled (it costs a look-up per vehicle).
    fn wants_received_paths(&self) -> bool {
        false
    }

    /// Whether [`VehicleView::received`] should be filled for vehicle `id` (default: as
    /// [`Self::wants_received_paths`]); lets an observer that shows only some vehicles spare
    /// the look-ups of the others.
    fn wants_received_paths_of(&self, _id: VehicleId) -> bool {
        self.wants_received_paths()
    }

    /// A vehicle has planned.
    fn on_plan(&mut self, _t_s: f64, _plan: &PlanView<'_, '_>) -> Result<(), SimError> {
        Ok(())
    }

    /// A logged instant.
    fn on_log(&mut self, _t_s: f64, _vehicles: &[VehicleView<'_>]) -> Result<(), SimError> {
        Ok(())
    }

    /// An event (collision, road-edge contact, fallback, lane change, near miss, …), typed;
    /// `Display` gives its event-log line and `SimEvent::level` its severity.
    fn on_event(&mut self, _event: &SimEvent) -> Result<(), SimError> {
        Ok(())
    }

    /// Whether the world should time the phases of its tick for this observer
    /// ([`Self::on_phase`]). Off by default: the clock reads cost about 1 % of a two-vehicle
    /// run, and the world reads the clock only while some observer asks.
    fn wants_phase_times(&self) -> bool {
        false
    }

    /// A phase of the tick took `wall` (wall time; not reproducible). Called only when some
    /// observer [wants phase times](Self::wants_phase_times); a phase may be reported in parts.
    fn on_phase(&mut self, _phase: Phase, _wall: Duration) {}

    /// A collision involving these vehicles.
    fn on_collision(&mut self, _ids: &[VehicleId]) {}

    /// The run has ended.
    fn finish(&mut self) -> Result<(), SimError> {
        Ok(())
    }
}
