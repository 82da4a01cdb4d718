//! The world's outputs: what each log instant hands to the observers and the recording,
//! and the run's outcome at its end.

use super::*;
use crate::outcome::TimeSeriesRow;

impl World {
    pub(super) fn log_instant(
        &mut self,
        t_s: f64,
        kins: &[Kinematics],
        bodies: &[BodyState],
    ) -> Result<(), SimError> {
        // Lane changes first (events), then the observers.
        self.log_lane_changes(t_s, kins)?;
        let samples: Vec<TimeSeriesRow> = self
            .agents
            .iter()
            .zip(kins)
            .map(|(a, k)| {
                let planned_speed_mps = planned_speed_at(&a.path, t_s).unwrap_or(k.speed_mps);
                TimeSeriesRow::at(t_s, &a.spec.name, k, planned_speed_mps)
            })
            .collect();
        let received: Vec<Vec<SharedLocalPath>> = self
            .agents
            .iter()
            .map(|a| {
                let wanted = self.recording.wants_received_paths_of(a.id)
                    || self
                        .observers
                        .iter()
                        .any(|o| o.wants_received_paths_of(a.id));
                if wanted && a.spec.connected {
                    self.bus.fresh_paths(a.id, t_s)
                } else {
                    Vec::new()
                }
            })
            .collect();
        let views: Vec<VehicleView<'_>> = self
            .agents
            .iter()
            .enumerate()
            .map(|(i, a)| VehicleView {
                id: a.id,
                kinematics: &kins[i],
                body: &bodies[i],
                sample: &samples[i],
                path: &a.path,
                connected: a.spec.connected,
                received: &received[i],
            })
            .collect();
        let started = self.timing.then(Instant::now);
        self.run_log.on_log(t_s, &views)?;
        self.traffic.on_log(t_s, &views)?;
        for observer in &mut self.observers {
            observer.on_log(t_s, &views)?;
        }
        let metrics = started.map(|s| s.elapsed());
        let started = self.timing.then(Instant::now);
        self.recording.on_log(t_s, &views)?;
        if !self.recorded.is_empty() {
            // Recorded traffic: drawn, not in the time series (`recorded` module doc).
            let names = self.names();
            let recorded = &bodies[self.agents.len()..];
            let labels: Vec<String> = recorded
                .iter()
                .map(|b| names.get(b.id as usize).cloned().unwrap_or_default())
                .collect();
            self.recording.log_recorded(recorded, &labels)?;
            if let Some(track) = self.recorded_track.as_mut() {
                track.extend(recorded.iter().zip(&labels).map(|(b, name)| {
                    crate::outcome::RecordedPose {
                        t_s,
                        vehicle: name.clone(),
                        x_m: b.x_m,
                        y_m: b.y_m,
                        yaw_rad: b.yaw_rad,
                        length_m: b.length_m,
                        width_m: b.width_m,
                    }
                }));
            }
        }
        let recording = started.map(|s| s.elapsed());
        drop(views);
        if let (Some(metrics), Some(recording)) = (metrics, recording) {
            self.phase_took(Phase::Metrics, metrics)?;
            self.phase_took(Phase::Recording, recording)?;
        }
        Ok(())
    }

    pub(super) fn finish(mut self) -> Result<RunOutcome, SimError> {
        let safety = self.safety.summary();
        if safety.near_miss {
            self.event(SimEvent::NearMiss {
                min_gap_m: safety.min_gap_m,
                min_ttc_s: safety.min_ttc_s,
            })?;
        }
        let traffic = self.traffic.summary(&safety);
        let planner_stats = self.planner_stats.stats();
        let vehicles = self.run_log.summaries();
        let v2v = self.bus.stats();
        let duration_s = self.time_s();
        let goals = self.goal_outcomes();
        self.each_observer(|o| o.finish())?;
        Ok(RunOutcome {
            duration_s,
            safety,
            traffic,
            vehicles,
            planner_stats,
            v2v,
            time_series: self.run_log.into_time_series(),
            recorded_track: self.recorded_track.unwrap_or_default(),
            profile: self.profile.as_ref().map(ProfileObserver::report),
            events: self.events,
            goals,
        })
    }
}

/// The speed the path asks for at time `t_s` (linear in time between its points).
fn planned_speed_at(path: &[PathPoint], t_s: f64) -> Option<f64> {
    let first = path.first()?;
    if t_s <= first.t_s {
        return Some(first.speed_mps);
    }
    for pair in path.windows(2) {
        if t_s <= pair[1].t_s {
            let span = pair[1].t_s - pair[0].t_s;
            let w = if span > 0.0 {
                (t_s - pair[0].t_s) / span
            } else {
                1.0
            };
            return Some(pair[0].speed_mps + w * (pair[1].speed_mps - pair[0].speed_mps));
        }
    }
    path.last().map(|p| p.speed_mps)
}
