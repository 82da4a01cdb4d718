//! The built-in observer that writes the Rerun recording: the road once, then the vehicles'
//! boxes, their planned and received paths and time series at every logged instant, each
//! planning vehicle's potential field at the field period, and the events.

use crate::error::SimError;
use crate::event::SimEvent;
use crate::observer::{PlanView, TickObserver, VehicleView};
use crate::recording::{Recorder, RecordingError};
use crate::safety::BodyState;
use mergesim_types::GridSpec;

fn rec(e: RecordingError) -> SimError {
    SimError::Recording(e.to_string())
}

/// The field window: 120 m of road from 20 m behind the vehicle, the whole road's width, 0.5 m
/// cells.
/// Length of the recorded field's window along x: 20 m behind the ego to 100 m ahead (m).
const FIELD_BEHIND_M: f64 = 20.0;
const FIELD_AHEAD_M: f64 = 100.0;
/// Spacing of the bound samples that find the road's lateral extent in the window (m).
const FIELD_BOUND_SAMPLE_M: f64 = 2.0;
/// At most this many rows (a 200 m tall window at 0.5 m): a road crossing the window steeply.
const FIELD_MAX_ROWS: usize = 400;

/// The grid the potential field is recorded on: 0.5 m cells, x from 20 m behind the ego to
/// 100 m ahead, y over the lanes' bounds within that x window (on the straight merge road its
/// bottom to top edge, as before; on a curve as far as the road reaches across the window).
fn field_grid(x_m: f64, y_m: f64, lanes: &mergesim_types::lanes::LaneRoad) -> GridSpec {
    use mergesim_types::lanes::Side;
    let cell_m = 0.5;
    let (x_lo, x_hi) = (x_m - FIELD_BEHIND_M, x_m + FIELD_AHEAD_M);
    let (mut y_lo, mut y_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for lane in lanes.lanes() {
        let length_m = lane.length_m();
        let samples = (length_m / FIELD_BOUND_SAMPLE_M).ceil().max(1.0) as usize;
        for k in 0..=samples {
            let s_m = length_m * k as f64 / samples as f64;
            for side in [Side::Left, Side::Right] {
                let [px, py] = lane.point(s_m, lane.bound_d_m(side, s_m));
                if (x_lo..=x_hi).contains(&px) {
                    y_lo = y_lo.min(py);
                    y_hi = y_hi.max(py);
                }
            }
        }
    }
    if !(y_lo.is_finite() && y_hi.is_finite() && y_hi > y_lo) {
        (y_lo, y_hi) = (y_m - 5.0, y_m + 5.0);
    }
    GridSpec {
        x_min_m: x_lo,
        y_min_m: y_lo,
        cell_m,
        columns: ((x_hi - x_lo) / cell_m).round() as usize,
        rows: (((y_hi - y_lo) / cell_m).ceil() as usize).min(FIELD_MAX_ROWS),
    }
}

/// Writes a run into a [`Recorder`] (a disabled one makes this a no-op).
pub struct RecordingObserver {
    recorder: Option<Recorder>,
    /// Fields and received paths for vehicle ids below this (`RecorderParams::detail_vehicles`).
    detail_below: usize,
}

impl RecordingObserver {
    /// Records into `recorder`, starting with the road (as lanes).
    pub fn new(
        mut recorder: Recorder,
        lanes: &mergesim_types::lanes::LaneRoad,
    ) -> Result<Self, SimError> {
        recorder.log_road(lanes).map_err(rec)?;
        let detail_below = recorder.params().detail_vehicles.unwrap_or(usize::MAX);
        Ok(Self {
            recorder: Some(recorder),
            detail_below,
        })
    }

    fn enabled(&mut self) -> Option<&mut Recorder> {
        self.recorder.as_mut().filter(|r| r.is_enabled())
    }

    /// Draws the recorded vehicles present at `t_s` (after [`TickObserver::on_log`] of the same
    /// instant, which sets the time): `names[i]` labels `bodies[i]`.
    pub fn log_recorded(&mut self, bodies: &[BodyState], names: &[String]) -> Result<(), SimError> {
        let Some(recorder) = self.enabled() else {
            return Ok(());
        };
        recorder.log_recorded_vehicles(bodies, names).map_err(rec)
    }
}

impl TickObserver for RecordingObserver {
    fn wants_received_paths(&self) -> bool {
        self.recorder.as_ref().is_some_and(Recorder::is_enabled)
    }

    fn wants_received_paths_of(&self, id: mergesim_types::VehicleId) -> bool {
        (id as usize) < self.detail_below && self.wants_received_paths()
    }

    fn on_plan(&mut self, _t_s: f64, plan: &PlanView<'_, '_>) -> Result<(), SimError> {
        if !plan.field_due || plan.observation.ego_id as usize >= self.detail_below {
            return Ok(());
        }
        let Some(recorder) = self.enabled() else {
            return Ok(());
        };
        let spec = field_grid(
            plan.observation.ego.x_m,
            plan.observation.ego.y_m,
            plan.observation.lanes,
        );
        if let Some(values) = (plan.field)(&spec) {
            recorder
                .log_field(
                    plan.name,
                    spec.x_min_m,
                    spec.y_min_m,
                    spec.cell_m,
                    spec.columns,
                    spec.rows,
                    &values,
                )
                .map_err(rec)?;
        }
        Ok(())
    }

    fn on_log(&mut self, t_s: f64, vehicles: &[VehicleView<'_>]) -> Result<(), SimError> {
        let detail_below = self.detail_below;
        let Some(recorder) = self.enabled() else {
            return Ok(());
        };
        recorder.set_time(t_s).map_err(rec)?;
        let bodies: Vec<BodyState> = vehicles.iter().map(|v| *v.body).collect();
        let names: Vec<String> = vehicles.iter().map(|v| v.sample.vehicle.clone()).collect();
        recorder.log_vehicles(&bodies, &names).map_err(rec)?;
        for v in vehicles {
            let k = v.kinematics;
            recorder
                .log_scalars(
                    &v.sample.vehicle,
                    &[
                        ("sideslip_rad", k.sideslip_rad),
                        ("yaw_rad", k.yaw_rad),
                        ("yaw_rate_radps", k.yaw_rate_radps),
                        ("speed_mps", k.speed_mps),
                        ("planned_speed_mps", v.sample.planned_speed_mps),
                    ],
                )
                .map_err(rec)?;
            recorder
                .log_planned_path(&v.sample.vehicle, v.path)
                .map_err(rec)?;
            if v.connected && (v.id as usize) < detail_below {
                recorder
                    .log_received_paths(&v.sample.vehicle, v.received)
                    .map_err(rec)?;
            }
        }
        Ok(())
    }

    fn on_event(&mut self, event: &SimEvent) -> Result<(), SimError> {
        if let Some(recorder) = self.recorder.as_mut() {
            recorder
                .log_event(&event.to_string(), event.level())
                .map_err(rec)?;
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<(), SimError> {
        match self.recorder.take() {
            Some(recorder) => recorder.finish().map_err(rec),
            None => Ok(()),
        }
    }
}
