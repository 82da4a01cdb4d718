//! Where a recorded vehicle is at any time of the run: its recorded states interpolated, and the
//! checks its data must pass before a world spawns it.
//!
//! # Interpolation
//! Between two consecutive states i and i + 1 (times t_i < t_{i+1}), with
//! w = (t − t_i) / (t_{i+1} − t_i):
//! - position and speed are linear in time: p = p_i + w (p_{i+1} − p_i);
//! - the heading turns along the shorter arc: h = h_i + w · wrap(h_{i+1} − h_i), wrap into
//!   [−π, π) (a recording crossing ±π does not spin the vehicle round), and is returned in
//!   [−π, π).
//!
//! At a sample's time the sample is returned exactly. The vehicle exists from its first state's
//! time to its last's, both included; outside that span [`RecordedVehicle::state_at`] is `None`.
//! A vehicle with a single state (a CommonRoad static obstacle, or a parked car) exists for the
//! whole run and stands still at that state's position and heading: speed 0, whatever its
//! recorded time and speed.

use mergesim_types::angle::wrap_angle_rad;

use crate::error::SimError;
use crate::recorded_traffic::{RecordedState, RecordedTraffic, RecordedVehicle};

impl RecordedVehicle {
    /// Its state at time `t_s` (module doc); `None` outside its recorded span.
    pub fn state_at(&self, t_s: f64) -> Option<RecordedState> {
        let first = self.states.first()?;
        if self.states.len() == 1 {
            return Some(RecordedState {
                time_s: t_s,
                speed_mps: 0.0,
                ..*first
            });
        }
        let last = self.states.last()?;
        if !(t_s >= first.time_s && t_s <= last.time_s) {
            return None;
        }
        // The first state later than t (there is one unless t is the last state's time).
        let next = self.states.partition_point(|s| s.time_s <= t_s);
        if next >= self.states.len() {
            return Some(*last);
        }
        let a = self.states[next - 1];
        let b = self.states[next];
        if t_s == a.time_s {
            return Some(a);
        }
        let w = (t_s - a.time_s) / (b.time_s - a.time_s);
        let lerp = |x: f64, y: f64| x + w * (y - x);
        Some(RecordedState {
            time_s: t_s,
            position_m: [
                lerp(a.position_m[0], b.position_m[0]),
                lerp(a.position_m[1], b.position_m[1]),
            ],
            heading_rad: wrap_angle_rad(
                a.heading_rad + w * wrap_angle_rad(b.heading_rad - a.heading_rad),
            ),
            speed_mps: lerp(a.speed_mps, b.speed_mps),
        })
    }

    /// Whether it exists for the whole run (a single state).
    pub fn is_stationary(&self) -> bool {
        self.states.len() == 1
    }

    /// The largest recorded speed (m/s): its desired speed once IDM drives it (reactive mode).
    pub fn max_speed_mps(&self) -> f64 {
        self.states.iter().map(|s| s.speed_mps).fold(0.0, f64::max)
    }
}

impl RecordedTraffic {
    /// Checks what a world needs: every vehicle has a non-empty unique name (also distinct from
    /// `other_names`, the simulated vehicles'), positive finite length and width, at least one
    /// state, finite values, a speed ≥ 0 and strictly increasing times. The error names the
    /// field as `recorded_traffic.vehicles[NAME].…`.
    pub fn validate(&self, other_names: &[String]) -> Result<(), SimError> {
        let mut names: std::collections::BTreeSet<&str> =
            other_names.iter().map(String::as_str).collect();
        for (index, v) in self.vehicles.iter().enumerate() {
            let label = if v.name.is_empty() {
                format!("#{index}")
            } else {
                v.name.clone()
            };
            let bad = |field: &str, message: String| SimError::InvalidField {
                field: format!("recorded_traffic.vehicles[{label}].{field}"),
                message,
            };
            if v.name.is_empty() {
                return Err(bad("name", "must not be empty".into()));
            }
            if !names.insert(v.name.as_str()) {
                return Err(bad(
                    "name",
                    format!("{} is used by another vehicle", v.name),
                ));
            }
            for (field, value) in [("length_m", v.length_m), ("width_m", v.width_m)] {
                if !(value.is_finite() && value > 0.0 && value <= 100.0) {
                    return Err(bad(field, format!("{value} must lie in (0, 100] m")));
                }
            }
            if v.states.is_empty() {
                return Err(bad("states", "needs at least one state".into()));
            }
            for (k, s) in v.states.iter().enumerate() {
                let values = [
                    ("time_s", s.time_s),
                    ("position_m[0]", s.position_m[0]),
                    ("position_m[1]", s.position_m[1]),
                    ("heading_rad", s.heading_rad),
                    ("speed_mps", s.speed_mps),
                ];
                if let Some((field, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
                    return Err(bad(
                        &format!("states[{k}].{field}"),
                        format!("{value} is not finite"),
                    ));
                }
                if s.speed_mps < 0.0 {
                    return Err(bad(
                        &format!("states[{k}].speed_mps"),
                        format!("{} must be >= 0", s.speed_mps),
                    ));
                }
                if k > 0 && s.time_s <= v.states[k - 1].time_s {
                    return Err(bad(
                        &format!("states[{k}].time_s"),
                        format!(
                            "{} s must be later than the previous state's {} s",
                            s.time_s,
                            v.states[k - 1].time_s
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}
