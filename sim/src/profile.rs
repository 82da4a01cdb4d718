//! Where a run's wall time goes (`RunOptions::profile`, `merge_sim run --profile`): each phase
//! of the tick timed with a monotonic clock. Off by default (the clock reads cost ≈ 1 % of a
//! two-vehicle run); wall-clock figures are not part of the determinism contract.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// A phase of the tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// V2V delivery.
    V2v,
    /// Building observations, the behaviours' decisions, their events, and broadcasting.
    Planning,
    /// The trackers (pure pursuit + PID).
    Tracking,
    /// Tire, suspension, drive and brake forces.
    TireForces,
    /// Rapier's step.
    Physics,
    /// Parry's safety checks (distances, TTC, contacts).
    Safety,
    /// Metrics, time series and user observers at the log period.
    Metrics,
    /// The Rerun recording (vehicles, paths, fields, plots).
    Recording,
}

impl Phase {
    /// Every phase, in tick order.
    pub(crate) const ALL: [Phase; 8] = [
        Phase::V2v,
        Phase::Planning,
        Phase::Tracking,
        Phase::TireForces,
        Phase::Physics,
        Phase::Safety,
        Phase::Metrics,
        Phase::Recording,
    ];

    /// Its name in reports.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Phase::V2v => "v2v",
            Phase::Planning => "planning",
            Phase::Tracking => "tracking",
            Phase::TireForces => "tire_forces",
            Phase::Physics => "physics",
            Phase::Safety => "safety",
            Phase::Metrics => "metrics",
            Phase::Recording => "recording",
        }
    }
}

/// Accumulates wall time per phase when enabled; every call is a no-op otherwise.
#[derive(Clone, Debug, Default)]
pub(crate) struct Profiler {
    enabled: bool,
    totals: [Duration; Phase::ALL.len()],
}

impl Profiler {
    /// A profiler that measures (`enabled`) or does nothing.
    pub(crate) fn new(enabled: bool) -> Self {
        Self {
            enabled,
            totals: Default::default(),
        }
    }

    /// Now, if measuring.
    pub(crate) fn start(&self) -> Option<Instant> {
        self.enabled.then(Instant::now)
    }

    /// Adds the time since `started` (from [`Self::start`]) to `phase`.
    pub fn stop(&mut self, phase: Phase, started: Option<Instant>) {
        if let Some(started) = started {
            self.add(phase, started.elapsed());
        }
    }

    /// Adds `elapsed` to `phase`.
    pub(crate) fn add(&mut self, phase: Phase, elapsed: Duration) {
        if self.enabled {
            self.totals[phase as usize] += elapsed;
        }
    }

    /// The report (None when not measuring).
    pub(crate) fn report(&self) -> Option<ProfileReport> {
        self.enabled.then(|| ProfileReport {
            phases: Phase::ALL
                .iter()
                .map(|&p| PhaseTime {
                    phase: p.name().to_string(),
                    wall_s: self.totals[p as usize].as_secs_f64(),
                })
                .collect(),
        })
    }
}

/// Wall time of one phase over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhaseTime {
    /// The phase (`planning`, `physics`, …).
    pub phase: String,
    /// Its wall time over the run (s).
    pub wall_s: f64,
}

/// Where a run's wall time went.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProfileReport {
    /// Every phase, in tick order.
    pub phases: Vec<PhaseTime>,
}

impl ProfileReport {
    /// The sum over the phases (s).
    pub fn total_s(&self) -> f64 {
        self.phases.iter().map(|p| p.wall_s).sum()
    }

    /// A table for the terminal: each phase's time and share.
    pub fn table(&self) -> String {
        let total = self.total_s().max(1e-12);
        let mut text = String::from("phase           wall s    share\n");
        for p in &self.phases {
            text.push_str(&format!(
                "{:<14} {:>8.3} {:>7.1} %\n",
                p.phase,
                p.wall_s,
                100.0 * p.wall_s / total
            ));
        }
        text.push_str(&format!("{:<14} {:>8.3}\n", "total", self.total_s()));
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disabled_profiler_measures_nothing_and_an_enabled_one_adds_up() {
        let mut off = Profiler::new(false);
        assert!(off.start().is_none());
        off.add(Phase::Physics, Duration::from_millis(5));
        assert!(off.report().is_none());
        let mut on = Profiler::new(true);
        on.add(Phase::Physics, Duration::from_millis(5));
        on.add(Phase::Planning, Duration::from_millis(15));
        let report = on.report().unwrap();
        assert!((report.total_s() - 0.020).abs() < 1e-12);
        assert!(report.table().contains("planning"));
        assert!(report.table().contains("75.0 %"), "{}", report.table());
    }
}
