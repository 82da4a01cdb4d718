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
//!
//! A broadcast reaches only the connected vehicles whose centres are within `range_m` of the
//! sender when it is sent (300 m, DSRC's range; docs/parameters.md); the world finds them with
//! the X sweep of `crate::spatial`, so a round of broadcasts costs O(N log N + k), not O(N²).
//! A receiver's inbox forgets paths once they are stale (they could never be used again).

use std::collections::BTreeMap;

use mergesim_types::{SharedLocalPath, VehicleId};
use serde::{Deserialize, Serialize};

use mergesim_types::bounds::{self, Bound};

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
    /// Radio range (m): a broadcast reaches the connected vehicles whose centres are within it
    /// at the time of sending. 300 m, DSRC's (docs/parameters.md).
    pub range_m: f64,
}

/// Default of [`V2vParams::range_m`]: DSRC (IEEE 802.11p) reaches about 300 m (NHTSA, *V2V
/// Communications: Readiness of V2V Technology for Application*, 2014).
pub(crate) const DEFAULT_V2V_RANGE_M: f64 = 300.0;

impl Default for V2vParams {
    fn default() -> Self {
        Self {
            latency_s: 0.0,
            drop_probability: 0.0,
            broadcast_period_s: 0.0,
            stale_after_s: 0.5,
            jitter_s: 0.0,
            duplicate_probability: 0.0,
            range_m: DEFAULT_V2V_RANGE_M,
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
    Bound::closed("range_m", 1.0, 1e5, "m"),
];

impl V2vParams {
    /// Checks every field against [`V2V_BOUNDS`]; the error names it.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
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
                ("range_m", self.range_m),
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
pub(crate) struct V2vBus {
    params: V2vParams,
    rng: SplitMix64,
    /// Jitter and duplicates (a stream of its own: see the module doc).
    fault_rng: SplitMix64,
    in_flight: Vec<InFlight>,
    /// Earliest `deliver_at_s` in flight (+∞ when none): `deliver` returns at once before it.
    next_due_s: f64,
    /// receiver → sender → newest delivered path.
    inbox: BTreeMap<VehicleId, BTreeMap<VehicleId, SharedLocalPath>>,
    last_broadcast_s: BTreeMap<VehicleId, f64>,
    stats: V2vStats,
}

impl V2vBus {
    /// A bus with its own random stream (drops) seeded by `seed`.
    pub(crate) fn new(params: V2vParams, seed: u64) -> Result<Self, SimError> {
        params.validate()?;
        Ok(Self {
            params,
            rng: SplitMix64::new(seed),
            fault_rng: SplitMix64::new(SplitMix64::derive(seed, 1)),
            in_flight: Vec::new(),
            next_due_s: f64::INFINITY,
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
    pub(crate) fn stats(&self) -> V2vStats {
        self.stats
    }

    /// Whether `sender` may broadcast at `t_s` given the broadcast period.
    pub(crate) fn may_broadcast(&self, sender: VehicleId, t_s: f64) -> bool {
        match self.last_broadcast_s.get(&sender) {
            None => true,
            // A small tolerance so a period equal to the planner period is not skipped by rounding.
            Some(last) => t_s - last >= self.params.broadcast_period_s - 1e-9,
        }
    }

    /// Broadcasts `message` at `t_s` to `receivers` (the sender itself is skipped). Returns false
    /// when the broadcast period has not elapsed (nothing sent).
    pub(crate) fn broadcast(
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
                let deliver_at_s = t_s + self.params.latency_s + jitter_s;
                self.next_due_s = self.next_due_s.min(deliver_at_s);
                self.in_flight.push(InFlight {
                    deliver_at_s,
                    receiver,
                    message: message.clone(),
                });
            }
        }
        self.deliver(t_s);
        true
    }

    /// Delivers every message whose delivery time has come (in send order). Costs nothing
    /// until the earliest message in flight is due.
    pub(crate) fn deliver(&mut self, t_s: f64) {
        if self.next_due_s > t_s + 1e-12 {
            return;
        }
        let mut kept = Vec::with_capacity(self.in_flight.len());
        let mut next_due_s = f64::INFINITY;
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
                next_due_s = next_due_s.min(item.deliver_at_s);
                kept.push(item);
            }
        }
        self.in_flight = kept;
        self.next_due_s = next_due_s;
    }

    /// Forgets the paths that are stale at `t_s`. Changes no result: time only advances, so a
    /// stale path stays stale, and a message older than a forgotten one that arrives later is
    /// stale as well ([`Self::fresh_paths`] never returns either). It keeps each inbox as small
    /// as the set of senders heard recently, rather than every sender ever heard.
    pub(crate) fn forget_stale(&mut self, t_s: f64) {
        let stale_after_s = self.params.stale_after_s;
        for by_sender in self.inbox.values_mut() {
            by_sender.retain(|_, p| is_fresh(p.stamp_s, t_s, stale_after_s));
        }
    }

    /// The fresh paths `receiver` holds at `t_s`, ordered by sender id.
    pub(crate) fn fresh_paths(&self, receiver: VehicleId, t_s: f64) -> Vec<SharedLocalPath> {
        self.inbox
            .get(&receiver)
            .map(|by_sender| {
                by_sender
                    .values()
                    .filter(|p| is_fresh(p.stamp_s, t_s, self.params.stale_after_s))
                    .cloned()
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// Whether a path stamped `stamp_s` is fresh at `t_s` (not older than `stale_after_s`).
fn is_fresh(stamp_s: f64, t_s: f64, stale_after_s: f64) -> bool {
    t_s - stamp_s <= stale_after_s + 1e-12
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::{TimedWaypoint, VehicleShape};

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

    #[test]
    fn forgetting_stale_paths_changes_nothing_a_receiver_sees() {
        let params = V2vParams {
            latency_s: 0.05,
            jitter_s: 0.8,
            duplicate_probability: 0.3,
            drop_probability: 0.2,
            stale_after_s: 0.3,
            ..V2vParams::default()
        };
        let mut kept = V2vBus::new(params.clone(), 11).unwrap();
        let mut pruned = V2vBus::new(params, 11).unwrap();
        for k in 0..2000 {
            let t_s = 0.01 * k as f64;
            for bus in [&mut kept, &mut pruned] {
                bus.deliver(t_s);
                if k % 10 == 0 {
                    for sender in 0..3 {
                        bus.broadcast(t_s, &msg(sender, t_s), &[0, 1, 2, 3]);
                    }
                }
            }
            pruned.forget_stale(t_s);
            for receiver in 0..4 {
                assert_eq!(
                    kept.fresh_paths(receiver, t_s),
                    pruned.fresh_paths(receiver, t_s),
                    "t = {t_s}"
                );
            }
        }
        assert_eq!(kept.stats(), pruned.stats());
        let held = |bus: &V2vBus| bus.inbox.values().map(BTreeMap::len).sum::<usize>();
        assert!(held(&pruned) <= held(&kept));
        pruned.forget_stale(1e3);
        assert_eq!(held(&pruned), 0);
        assert!(held(&kept) > 0);
    }
}
