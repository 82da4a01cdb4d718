//! What happens during a run, as typed events (in the manner of Rapier's `CollisionEvent`):
//! the world hands each to its observers ([`crate::TickObserver::on_event`]) and keeps them in
//! [`crate::RunOutcome::events`]. They are formatted only at the edges: `Display` gives the line
//! of the event log (the text of `merge_sim run`, the JSON summary's `events` and the
//! recording's event log), [`SimEvent::level`] its severity.

use std::fmt;

use mergesim_types::lanes::LaneId;
use mergesim_types::{DegradedMode, FallbackReason};
use serde::{Deserialize, Serialize};

use crate::recording::EventLevel;
use crate::safety::{CollisionEvent, RoadEdge};

/// One event of a run. Vehicles are named as in the scenario (recorded vehicles by their
/// recording's names).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SimEvent {
    /// Two vehicles started touching (the safety monitor's exact check).
    Collision {
        /// The safety monitor's event.
        event: CollisionEvent,
        /// The name of `event.id_a`.
        vehicle_a: String,
        /// The name of `event.id_b`.
        vehicle_b: String,
    },
    /// A vehicle started touching or crossing a road edge.
    EdgeContact {
        /// The checked instant (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// Which edge.
        edge: RoadEdge,
    },
    /// A recorded vehicle handed over to IDM (reactive recorded traffic).
    RecordedHandover {
        /// The world's time at the handover (s).
        t_s: f64,
        /// The recorded vehicle.
        vehicle: String,
        /// The simulated vehicle ahead.
        leader: String,
        /// The bumper gap the recording would have left at the next step (m).
        gap_m: f64,
        /// IDM's safe gap s* there (m).
        safe_gap_m: f64,
        /// Its recorded speed at the next step (m/s).
        speed_mps: f64,
        /// Its approach rate Δv to the leader (m/s).
        approach_rate_mps: f64,
    },
    /// A vehicle reached its goal (`crate::goal`).
    GoalReached {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// Where: x (m).
        x_m: f64,
        /// Where: y (m).
        y_m: f64,
        /// Its speed (m/s).
        speed_mps: f64,
    },
    /// A vehicle's front passed the open end of a lane: the run ends.
    LeftMap {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// The lane whose open end it passed.
        lane: LaneId,
    },
    /// A vehicle moved into a neighbouring lane (or across).
    LaneChange {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// `left`, `right` or `across`.
        direction: String,
        /// The lane it left.
        from_lane: LaneId,
        /// The lane it entered.
        to_lane: LaneId,
        /// Where: x (m).
        x_m: f64,
        /// Where: y (m).
        y_m: f64,
    },
    /// A shielded vehicle's pair with another turned RSS-dangerous (`crate::shield`): the
    /// shield bounds its planner's paths by the proper response until it is no longer.
    ShieldIntervened {
        /// When (s).
        t_s: f64,
        /// The shielded vehicle.
        vehicle: String,
        /// The other vehicle of the dangerous pair.
        other: String,
        /// The proper response: `longitudinal`, `lateral` or `longitudinal+lateral`.
        response: String,
        /// The bumper-to-bumper gap along the lane (m).
        lon_gap_m: f64,
        /// The safe longitudinal gap (m).
        safe_lon_gap_m: f64,
    },
    /// A vehicle's planner entered a degraded mode (`Decision::degraded_mode`).
    DegradedModeEntered {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// The mode (e.g. `v2v-lost`).
        mode: DegradedMode,
    },
    /// A vehicle's planner left its degraded mode.
    DegradedModeLeft {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// The mode it left.
        mode: DegradedMode,
    },
    /// A vehicle's planner fell back (`Decision::fallback`).
    PlannerFallback {
        /// When (s).
        t_s: f64,
        /// The vehicle.
        vehicle: String,
        /// Why.
        reason: FallbackReason,
    },
    /// At the end of a run: the closest approach came within the near-miss thresholds.
    NearMiss {
        /// The run's minimum gap (m), if any pair was followed.
        min_gap_m: Option<f64>,
        /// The run's minimum TTC (s), if any pair was closing.
        min_ttc_s: Option<f64>,
    },
}

impl SimEvent {
    /// The severity the event log and the recording give it.
    pub(crate) fn level(&self) -> EventLevel {
        match self {
            Self::Collision { .. } | Self::EdgeContact { .. } => EventLevel::Error,
            Self::RecordedHandover { .. } | Self::GoalReached { .. } | Self::LaneChange { .. } => {
                EventLevel::Info
            }
            Self::LeftMap { .. }
            | Self::ShieldIntervened { .. }
            | Self::DegradedModeEntered { .. }
            | Self::DegradedModeLeft { .. }
            | Self::PlannerFallback { .. }
            | Self::NearMiss { .. } => EventLevel::Warn,
        }
    }
}

impl fmt::Display for SimEvent {
    /// The event log's line.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Collision {
                event,
                vehicle_a,
                vehicle_b,
            } => {
                let contact = event
                    .t_contact_estimate_s
                    .map(|t| format!(", first contact at {t:.3} s"))
                    .unwrap_or_default();
                let cause = if event.caused_by_replay {
                    " (a recorded vehicle ran into a simulated one from behind: caused by the \
                     replay)"
                } else {
                    ""
                };
                write!(
                    f,
                    "collision {vehicle_a} / {vehicle_b} at t = {:.3} s{contact}, relative speed \
                     {:.2} m/s{cause}",
                    event.t_s, event.relative_speed_mps
                )
            }
            Self::EdgeContact { t_s, vehicle, edge } => {
                write!(
                    f,
                    "t = {t_s:.3} s: vehicle {vehicle} hit the {edge:?} road edge"
                )
            }
            Self::RecordedHandover {
                t_s,
                vehicle,
                leader,
                gap_m,
                safe_gap_m,
                speed_mps,
                approach_rate_mps,
            } => write!(
                f,
                "t = {t_s:.3} s: recorded vehicle {vehicle} hands over to IDM behind {leader}: its \
                 recording would leave a gap of {gap_m:.3} m < s* = {safe_gap_m:.3} m (v = \
                 {speed_mps:.2} m/s, Δv = {approach_rate_mps:.2} m/s)"
            ),
            Self::GoalReached {
                t_s,
                vehicle,
                x_m,
                y_m,
                speed_mps,
            } => write!(
                f,
                "t = {t_s:.2} s: {vehicle} reached its goal at x = {x_m:.1} m, y = {y_m:.1} m, \
                 {speed_mps:.2} m/s"
            ),
            Self::LeftMap { t_s, vehicle, lane } => write!(
                f,
                "t = {t_s:.2} s: {vehicle} left the map (its front passed the open end of lane \
                 {lane}); the run ends here"
            ),
            Self::LaneChange {
                t_s,
                vehicle,
                direction,
                from_lane,
                to_lane,
                x_m,
                y_m,
            } => write!(
                f,
                "t = {t_s:.2} s: {vehicle} changed lanes {direction}, from lane {from_lane} to \
                 lane {to_lane}, at x = {x_m:.1} m, y = {y_m:.1} m"
            ),
            Self::ShieldIntervened {
                t_s,
                vehicle,
                other,
                response,
                lon_gap_m,
                safe_lon_gap_m,
            } => write!(
                f,
                "t = {t_s:.2} s: the shield of {vehicle} intervened ({response} response): \
                 {other} is RSS-dangerous, {lon_gap_m:.1} m apart where {safe_lon_gap_m:.1} m \
                 are safe"
            ),
            Self::DegradedModeEntered { t_s, vehicle, mode } => {
                write!(f, "t = {t_s:.2} s: {vehicle} plans in degraded mode {mode}")
            }
            Self::DegradedModeLeft { t_s, vehicle, mode } => {
                write!(f, "t = {t_s:.2} s: {vehicle} left degraded mode {mode}")
            }
            Self::PlannerFallback {
                t_s,
                vehicle,
                reason,
            } => write!(f, "t = {t_s:.2} s: planner fallback of {vehicle}: {reason}"),
            Self::NearMiss {
                min_gap_m,
                min_ttc_s,
            } => write!(
                f,
                "near miss: min gap {} m, min TTC {}",
                min_gap_m
                    .map(|g| format!("{g:.2}"))
                    .unwrap_or_else(|| "-".into()),
                min_ttc_s
                    .map(|t| format!("{t:.2} s"))
                    .unwrap_or_else(|| "none".into())
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_collision_reads_as_the_event_log_always_wrote_it() {
        let event = SimEvent::Collision {
            event: CollisionEvent {
                t_s: 3.25,
                id_a: 0,
                id_b: 1,
                t_contact_estimate_s: Some(3.2412),
                relative_speed_mps: 4.5,
                caused_by_replay: false,
            },
            vehicle_a: "ego".into(),
            vehicle_b: "obstacle".into(),
        };
        assert_eq!(
            event.to_string(),
            "collision ego / obstacle at t = 3.250 s, first contact at 3.241 s, relative speed \
             4.50 m/s"
        );
        assert_eq!(event.level(), EventLevel::Error);
        // The JSON form is tagged by kind and reads back.
        let json = serde_json::to_string(&event).unwrap();
        assert!(json.starts_with(r#"{"kind":"collision""#), "{json}");
        assert_eq!(serde_json::from_str::<SimEvent>(&json).unwrap(), event);
    }

    #[test]
    fn a_degraded_mode_is_named_as_the_log_always_named_it() {
        let entered = SimEvent::DegradedModeEntered {
            t_s: 1.0,
            vehicle: "ego".into(),
            mode: DegradedMode::V2vLost,
        };
        assert_eq!(
            entered.to_string(),
            "t = 1.00 s: ego plans in degraded mode v2v-lost"
        );
        let left = SimEvent::DegradedModeLeft {
            t_s: 2.5,
            vehicle: "car".into(),
            mode: DegradedMode::Other("dead-reckoning".into()),
        };
        assert_eq!(
            left.to_string(),
            "t = 2.50 s: car left degraded mode dead-reckoning"
        );
        assert_eq!(
            serde_json::to_string(&DegradedMode::V2vLost).unwrap(),
            r#""v2v-lost""#
        );
    }

    #[test]
    fn a_near_miss_without_figures_says_so() {
        let event = SimEvent::NearMiss {
            min_gap_m: None,
            min_ttc_s: Some(1.234),
        };
        assert_eq!(event.to_string(), "near miss: min gap - m, min TTC 1.23 s");
        assert_eq!(event.level(), EventLevel::Warn);
    }
}
