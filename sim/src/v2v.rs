//! The V2V bus: shared local paths (SLP) broadcast by connected vehicles, delivered after a
//! latency, possibly dropped, and ignored once stale (step 1 of the tick).
//!
//! The paper assumes ideal communication (no latency, no loss): that is the default. Faults:
//! a fixed latency, random extra delay (`jitter_s`: messages of one sender can arrive out of
//! order), losses (`drop_probability`) and duplicated deliveries (`duplicate_probability`). A
//! receiver keeps the newest path of each sender by its time stamp, so a late or repeated
//! message never replaces a newer one. Drops come from one random stream and jitter and
//! duplicates from another, both seeded by the run's seed, so enabling jitter or duplicates
//! does not change which messages are dropped.

use std::collections::BTreeMap;

use planner::{SharedLocalPath, VehicleId};
use serde::{Deserialize, Serialize};

use mergesim_types::{Bound, bounds};

use crate::error::SimError;
use crate::rng::SplitMix64;

/// Communication parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct V2vParams {
    /// Delay between broadcast and delivery (s).
    pub latency_s: f64,
    /// Probability that one receiver misses one message (independent draws, seeded).
    pub drop_probability: f64,
    /// Minimum time between two broadcasts of the same vehicle (s); 0 = every plan.
    pub broadcast_period_s: f64,
    /// A received path older than this (by its time stamp) is ignored (s).
    pub stale_after_s: f64,
    /// Extra delay of each delivery, uniform in [0, jitter_s] (s): reorders messages whose
    /// send times are closer than the jitter.
    #[serde(default)]
    pub jitter_s: f64,
    /// Probability that a delivered message is delivered a second time, after another
    /// independent delay.
    #[serde(default)]
    pub duplicate_probability: f64,
}

impl Default for V2vParams {
    fn default() -> Self {
        Self {
            latency_s: 0.0,
            drop_probability: 0.0,
            broadcast_period_s: 0.0,
            stale_after_s: 0.5,
            jitter_s: 0.0,
            duplicate_probability: 0.0,
        }
    }
}

/// Allowed ranges of the V2V parameters (README "Limits").
pub const V2V_BOUNDS: &[Bound] = &[
    Bound::closed("latency_s", 0.0, 10.0, "s"),
    Bound::closed("drop_probability", 0.0, 1.0, ""),
    Bound::closed("broadcast_period_s", 0.0, 10.0, "s"),
    Bound::above("stale_after_s", 0.0, 60.0, "s"),
    Bound::closed("jitter_s", 0.0, 10.0, "s"),
    Bound::closed("duplicate_probability", 0.0, 1.0, ""),
];

impl V2vParams {
    /// Checks every field against [`V2V_BOUNDS`]; the error names it.
    pub fn validate(&self) -> Result<(), SimError> {
        bounds::check_all(
            "v2v",
            V2V_BOUNDS,
            &[
                ("latency_s", self.latency_s),
                ("drop_probability", self.drop_probability),
                ("broadcast_period_s", self.broadcast_period_s),
                ("stale_after_s", self.stale_after_s),
                ("jitter_s", self.jitter_s),
                ("duplicate_probability", self.duplicate_probability),
            ],
        )?;
        Ok(())
    }
}

/// A message on its way to one receiver.
#[derive(Clone, Debug)]
struct InFlight {
    deliver_at_s: f64,
    receiver: VehicleId,
    message: SharedLocalPath,
}

/// Counters of what the bus did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct V2vStats {
    /// Broadcasts made.
    pub broadcasts: u64,
    /// Per-receiver deliveries.
    pub delivered: u64,
    /// Per-receiver drops.
    pub dropped: u64,
    /// Extra deliveries of duplicated messages.
    #[serde(default)]
    pub duplicated: u64,
}

/// The bus. Everything is kept in ordered maps and vectors so delivery order is deterministic.
#[derive(Clone, Debug)]
pub struct V2vBus {
    params: V2vParams,
    rng: SplitMix64,
    /// Jitter and duplicates (a stream of its own: see the module doc).
    fault_rng: SplitMix64,
    in_flight: Vec<InFlight>,
    /// receiver → sender → newest delivered path.
    inbox: BTreeMap<VehicleId, BTreeMap<VehicleId, SharedLocalPath>>,
    last_broadcast_s: BTreeMap<VehicleId, f64>,
    stats: V2vStats,
}

impl V2vBus {
    /// A bus with its own random stream (drops) seeded by `seed`.
    pub fn new(params: V2vParams, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        Ok(Self {
            params,
            rng: SplitMix64::new(seed),
            fault_rng: SplitMix64::new(SplitMix64::derive(seed, 1)),
            in_flight: Vec::new(),
            inbox: BTreeMap::new(),
            last_broadcast_s: BTreeMap::new(),
            stats: V2vStats::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &V2vParams {
        &self.params
    }

    /// What happened so far.
    pub fn stats(&self) -> V2vStats {
        self.stats
    }

    /// Whether `sender` may broadcast at `t_s` given the broadcast period.
    pub fn may_broadcast(&self, sender: VehicleId, t_s: f64) -> bool {
        match self.last_broadcast_s.get(&sender) {
            None => true,
            // A small tolerance so a period equal to the planner period is not skipped by rounding.
            Some(last) => t_s - last >= self.params.broadcast_period_s - 1e-9,
        }
    }

    /// Broadcasts `message` at `t_s` to `receivers` (the sender itself is skipped). Returns false
    /// when the broadcast period has not elapsed (nothing sent).
    pub fn broadcast(
        &mut self,
        t_s: f64,
        message: &SharedLocalPath,
        receivers: &[VehicleId],
    ) -> bool {
        if !self.may_broadcast(message.vehicle_id, t_s) {
            return false;
        }
        self.last_broadcast_s.insert(message.vehicle_id, t_s);
        self.stats.broadcasts += 1;
        for &receiver in receivers {
            if receiver == message.vehicle_id {
                continue;
            }
            // One draw per receiver whatever the probability, so the stream does not depend on it.
            let draw = self.rng.next_f64();
            if draw < self.params.drop_probability {
                self.stats.dropped += 1;
                continue;
            }
            let copies = if self.params.duplicate_probability > 0.0
                && self.fault_rng.next_f64() < self.params.duplicate_probability
            {
                self.stats.duplicated += 1;
                2
            } else {
                1
            };
            for _ in 0..copies {
                let jitter_s = if self.params.jitter_s > 0.0 {
                    self.params.jitter_s * self.fault_rng.next_f64()
                } else {
                    0.0
                };
                self.in_flight.push(InFlight {
                    deliver_at_s: t_s + self.params.latency_s + jitter_s,
                    receiver,
                    message: message.clone(),
                });
            }
        }
        self.deliver(t_s);
        true
    }

    /// Delivers every message whose delivery time has come (in send order).
    pub fn deliver(&mut self, t_s: f64) {
        let mut kept = Vec::with_capacity(self.in_flight.len());
        for item in self.in_flight.drain(..) {
            if item.deliver_at_s <= t_s + 1e-12 {
                let slot = self.inbox.entry(item.receiver).or_default();
                let newer = slot
                    .get(&item.message.vehicle_id)
                    .is_none_or(|old| old.stamp_s <= item.message.stamp_s);
                if newer {
                    slot.insert(item.message.vehicle_id, item.message);
                }
                self.stats.delivered += 1;
            } else {
                kept.push(item);
            }
        }
        self.in_flight = kept;
    }

    /// The fresh paths `receiver` holds at `t_s`, ordered by sender id.
    pub fn fresh_paths(&self, receiver: VehicleId, t_s: f64) -> Vec<SharedLocalPath> {
        self.inbox
            .get(&receiver)
            .map(|by_sender| {
                by_sender
                    .values()
                    .filter(|p| t_s - p.stamp_s <= self.params.stale_after_s + 1e-12)
                    .cloned()
                    .collect()
            })
            .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use planner::{TimedWaypoint, VehicleShape};

    fn msg(id: VehicleId, stamp_s: f64) -> SharedLocalPath {
        SharedLocalPath {
            vehicle_id: id,
            stamp_s,
            shape: VehicleShape::default(),
            speed_mps: 10.0,
            waypoints: vec![TimedWaypoint {
                t_s: stamp_s,
                x_m: 0.0,
                y_m: 0.0,
            }],
        }
    }

    #[test]
    fn ideal_bus_delivers_at_once_to_others_only() {
        let mut bus = V2vBus::new(V2vParams::default(), 1).unwrap();
        assert!(bus.broadcast(0.0, &msg(0, 0.0), &[0, 1, 2]));
        assert_eq!(bus.fresh_paths(1, 0.0).len(), 1);
        assert_eq!(bus.fresh_paths(2, 0.0).len(), 1);
        assert!(bus.fresh_paths(0, 0.0).is_empty());
    }

    #[test]
    fn latency_delays_and_staleness_expires() {
        let params = V2vParams {
            latency_s: 0.1,
            stale_after_s: 0.3,
            ..V2vParams::default()
        };
        let mut bus = V2vBus::new(params, 1).unwrap();
        bus.broadcast(1.0, &msg(0, 1.0), &[1]);
        bus.deliver(1.05);
        assert!(bus.fresh_paths(1, 1.05).is_empty());
        bus.deliver(1.1);
        assert_eq!(bus.fresh_paths(1, 1.1).len(), 1);
        assert!(bus.fresh_paths(1, 1.31).is_empty());
    }

    #[test]
    fn drop_rate_matches_probability_and_is_seeded() {
        let params = V2vParams {
            drop_probability: 0.2,
            ..V2vParams::default()
        };
        let run = |seed| {
            let mut bus = V2vBus::new(params.clone(), seed).unwrap();
            for k in 0..10_000 {
                bus.broadcast(k as f64, &msg(0, k as f64), &[1]);
            }
            bus.stats()
        };
        let a = run(5);
        assert_eq!(a, run(5));
        let rate = a.dropped as f64 / 10_000.0;
        assert!((rate - 0.2).abs() < 0.015, "{rate}");
    }

    #[test]
    fn broadcast_period_is_respected() {
        let params = V2vParams {
            broadcast_period_s: 0.3,
            ..V2vParams::default()
        };
        let mut bus = V2vBus::new(params, 1).unwrap();
        assert!(bus.broadcast(0.0, &msg(0, 0.0), &[1]));
        assert!(!bus.broadcast(0.1, &msg(0, 0.1), &[1]));
        assert!(bus.broadcast(0.3, &msg(0, 0.3), &[1]));
    }

    #[test]
    fn bad_probability_is_named() {
        let params = V2vParams {
            drop_probability: 1.5,
            ..V2vParams::default()
        };
        let err = V2vBus::new(params, 1).unwrap_err().to_string();
        assert!(
            err.contains("v2v.drop_probability") && err.contains("1.5"),
            "{err}"
        );
    }

    #[test]
    fn late_and_repeated_messages_never_replace_newer_ones() {
        let params = V2vParams {
            latency_s: 0.05,
            jitter_s: 0.3,
            duplicate_probability: 0.5,
            stale_after_s: 10.0,
            ..V2vParams::default()
        };
        let mut bus = V2vBus::new(params, 9).unwrap();
        let mut reordered = 0;
        let mut newest_seen = f64::NEG_INFINITY;
        for k in 0..400 {
            let t_s = 0.1 * k as f64;
            bus.broadcast(t_s, &msg(0, t_s), &[1]);
            bus.deliver(t_s);
            let held = bus.fresh_paths(1, t_s);
            if let Some(path) = held.first() {
                // The held stamp never goes back, though deliveries arrive out of order.
                assert!(
                    path.stamp_s >= newest_seen,
                    "{} < {newest_seen}",
                    path.stamp_s
                );
                if path.stamp_s < t_s - 0.05 - 0.1 {
                    reordered += 1;
                }
                newest_seen = path.stamp_s;
            }
            assert!(held.len() <= 1, "one path per sender");
        }
        let stats = bus.stats();
        assert!(
            stats.duplicated > 150 && stats.duplicated < 250,
            "{stats:?}"
        );
        assert_eq!(stats.delivered, 400 + stats.duplicated - pending(&bus));
        assert!(
            reordered > 0,
            "the jitter must delay some messages past a later one"
        );
    }

    fn pending(bus: &V2vBus) -> u64 {
        bus.in_flight.len() as u64
    }

    #[test]
    fn jitter_and_duplicates_leave_the_drops_unchanged() {
        let run = |jitter_s, duplicate_probability| {
            let params = V2vParams {
                drop_probability: 0.3,
                jitter_s,
                duplicate_probability,
                ..V2vParams::default()
            };
            let mut bus = V2vBus::new(params, 4).unwrap();
            for k in 0..1000 {
                bus.broadcast(k as f64, &msg(0, k as f64), &[1, 2]);
            }
            bus.stats().dropped
        };
        assert_eq!(run(0.0, 0.0), run(0.5, 0.5));
    }
}
