//! The first-in-first-out crossing queue every connected car computes from what it hears, and
//! the crossing times it assigns.
//!
//! ## Order and times (Rios-Torres & Malikopoulos 2017: FIFO by entry into the control zone)
//!
//! Positions are arc lengths s along the through lane ([`super::geometry`]). A car joins the
//! queue the first time it is known inside the control zone, s ≥ s_m − L (s_m the merging
//! zone's entry). From that report (stamp t, position s, speed v, v̄ = max(v, v_floor)) it
//! *latches*
//!
//! ```text
//!   t_entry = t − (s − (s_m − L)) / v̄        entry into the control zone (extrapolated back)
//!   t_nom   = t + (s_m − s) / v̄              arrival at the merging zone cruising at v
//! ```
//!
//! and, once a report places it past s_m, its actual arrival t_arr = t − (s − s_m)/v̄. The
//! queue is sorted by (t_entry, id) and the crossing times follow, for the cars in order,
//!
//! ```text
//!   t_f,1 = max(t_nom,1, t_eff,0 + δ(0, 1))        (car 0: the last car that left the zone)
//!   t_f,i = max(t_nom,i, t_eff,i−1 + δ(i−1, i)),   t_eff,i = t_arr,i if latched, else t_f,i
//! ```
//!
//! δ(j, i) = δ (`headway_s`) when j and i came from the same lane, δ_side (`side_headway_s`)
//! otherwise. A car leaves the queue once a report places it past the merging zone's end; the
//! last car to leave is kept as car 0.
//!
//! ## Late, lost and duplicated messages
//!
//! Every latched value is a function of one report alone (its own stamp, position and speed),
//! never of the time it was received, so:
//! - **late** (stale) messages: a report is used at its stamp; a message older than the newest
//!   already heard from that car is ignored (it latches nothing new and moves nothing back);
//! - **duplicated** messages: a report with the stamp already heard is ignored (idempotent);
//! - **lost** messages: a car not heard keeps its latched slot (its t_entry, t_nom, t_arr and
//!   last position) for `message_timeout_s` after its last report's stamp, and is then dropped
//!   from the queue (it rejoins, with new latches, if heard again). If the first message that
//!   placed a car inside the control zone is lost, the next one latches values extrapolated
//!   from a later state: the cars that heard the first and those that did not may then hold
//!   slightly different t_entry / t_nom for it, and may disagree on the order only if two
//!   cars' t_entry lie within that difference. Each car's plan is still kept safe by its own
//!   rear-end constraint (`profile` module), which uses its perception, not the messages.
//!
//! With ideal V2V every car hears the same reports at the same stamps and computes the same
//! queue and times (a car latches its own values from its own state at its planning instant,
//! which is exactly the report it broadcasts).

use std::collections::BTreeMap;

use mergesim_types::VehicleId;

/// One car's report: from a received shared local path, or the ego's own state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Report {
    /// The car.
    pub id: VehicleId,
    /// Stamp (s).
    pub stamp_s: f64,
    /// Arc length along the through lane (m).
    pub s_m: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
    /// Whether it drives in the ending lane (else the through lane).
    pub on_ending_lane: bool,
}

/// Where the zones lie along the through lane (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Zones {
    /// s_m − L: the control zone's start.
    pub control_start_m: f64,
    /// s_m: the merging zone's entry.
    pub merge_start_m: f64,
    /// The merging zone's end (the lane end).
    pub merge_end_m: f64,
}

/// A car's latched values (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    /// t_entry (s).
    pub entry_s: f64,
    /// t_nom (s).
    pub nominal_arrival_s: f64,
    /// t_arr (s), once latched.
    pub arrival_s: Option<f64>,
    /// The lane it came from (latched at joining).
    pub from_ending_lane: bool,
    /// Its newest report.
    pub last: Report,
}

/// The last car that left the zone: its effective crossing time and lane.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Departed {
    crossing_s: f64,
    from_ending_lane: bool,
}

/// One car's slot: its place in the queue (0 = first) and its crossing time t_f.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot {
    /// Place in the queue.
    pub place: usize,
    /// t_f (s).
    pub crossing_s: f64,
}

/// The queue as one car knows it (module doc).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MergeQueue {
    members: BTreeMap<VehicleId, Member>,
    departed: Option<Departed>,
}

/// The queue's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueueSettings {
    /// δ (s).
    pub headway_s: f64,
    /// δ_side (s).
    pub side_headway_s: f64,
    /// Timeout of a car not heard (s).
    pub message_timeout_s: f64,
    /// v_floor of the extrapolations (m/s, > 0).
    pub speed_floor_mps: f64,
}

impl MergeQueue {
    /// An empty queue.
    pub fn new() -> Self {
        Self::default()
    }

    /// The members, by id.
    pub fn members(&self) -> &BTreeMap<VehicleId, Member> {
        &self.members
    }

    /// Takes in the reports of one planning instant `now_s` (the ego's and every heard one, in
    /// any order, duplicates allowed), then drops the cars not heard for longer than the
    /// timeout (module doc).
    pub fn update(&mut self, now_s: f64, reports: &[Report], zones: &Zones, set: &QueueSettings) {
        for r in reports {
            self.take(r, zones, set);
        }
        self.members
            .retain(|_, m| now_s - m.last.stamp_s <= set.message_timeout_s);
    }

    fn take(&mut self, r: &Report, zones: &Zones, set: &QueueSettings) {
        let finite = [r.stamp_s, r.s_m, r.speed_mps]
            .iter()
            .all(|x| x.is_finite());
        if !finite {
            return;
        }
        let v = r.speed_mps.max(set.speed_floor_mps);
        if let Some(m) = self.members.get_mut(&r.id) {
            if r.stamp_s <= m.last.stamp_s {
                return; // late or duplicated: nothing new.
            }
            m.last = *r;
            if m.arrival_s.is_none() && r.s_m >= zones.merge_start_m {
                m.arrival_s = Some(r.stamp_s - (r.s_m - zones.merge_start_m) / v);
            }
            if r.s_m >= zones.merge_end_m {
                let leaving = *m;
                self.members.remove(&r.id);
                let crossing_s = leaving.arrival_s.unwrap_or(leaving.nominal_arrival_s);
                if self.departed.is_none_or(|d| crossing_s >= d.crossing_s) {
                    self.departed = Some(Departed {
                        crossing_s,
                        from_ending_lane: leaving.from_ending_lane,
                    });
                }
            }
            return;
        }
        if r.s_m < zones.control_start_m || r.s_m >= zones.merge_end_m {
            return;
        }
        let arrival_s =
            (r.s_m >= zones.merge_start_m).then(|| r.stamp_s - (r.s_m - zones.merge_start_m) / v);
        self.members.insert(
            r.id,
            Member {
                entry_s: r.stamp_s - (r.s_m - zones.control_start_m) / v,
                nominal_arrival_s: arrival_s
                    .unwrap_or(r.stamp_s + (zones.merge_start_m - r.s_m) / v),
                arrival_s,
                from_ending_lane: r.on_ending_lane,
                last: *r,
            },
        );
    }

    /// Every member's slot in FIFO order (module doc): (id, slot).
    pub fn schedule(&self, set: &QueueSettings) -> Vec<(VehicleId, Slot)> {
        let mut order: Vec<(&VehicleId, &Member)> = self.members.iter().collect();
        order.sort_by(|a, b| a.1.entry_s.total_cmp(&b.1.entry_s).then(a.0.cmp(b.0)));
        let mut prev = self.departed;
        order
            .into_iter()
            .enumerate()
            .map(|(place, (id, m))| {
                let crossing_s = match prev {
                    Some(p) => {
                        let delta = if p.from_ending_lane == m.from_ending_lane {
                            set.headway_s
                        } else {
                            set.side_headway_s
                        };
                        m.nominal_arrival_s.max(p.crossing_s + delta)
                    }
                    None => m.nominal_arrival_s,
                };
                prev = Some(Departed {
                    crossing_s: m.arrival_s.unwrap_or(crossing_s),
                    from_ending_lane: m.from_ending_lane,
                });
                (*id, Slot { place, crossing_s })
            })
            .collect()
    }

    /// The slot of car `id`, if it is in the queue.
    pub fn slot_of(&self, id: VehicleId, set: &QueueSettings) -> Option<Slot> {
        self.schedule(set)
            .into_iter()
            .find(|(i, _)| *i == id)
            .map(|(_, s)| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ZONES: Zones = Zones {
        control_start_m: 0.0,
        merge_start_m: 150.0,
        merge_end_m: 250.0,
    };
    const SET: QueueSettings = QueueSettings {
        headway_s: 2.0,
        side_headway_s: 3.0,
        message_timeout_s: 1.0,
        speed_floor_mps: 0.5,
    };

    fn report(id: VehicleId, stamp_s: f64, s_m: f64, ending: bool) -> Report {
        Report {
            id,
            stamp_s,
            s_m,
            speed_mps: 15.0,
            on_ending_lane: ending,
        }
    }

    /// Three cars at 15 m/s: A (through) at 30 m, B (ending) at 15 m, C (through) at 0 m.
    fn three(now_s: f64) -> Vec<Report> {
        vec![
            report(3, now_s, 0.0, false),
            report(1, now_s, 30.0, false),
            report(2, now_s, 15.0, true),
        ]
    }

    #[test]
    fn fifo_order_and_headways_by_hand() {
        let mut q = MergeQueue::new();
        q.update(0.0, &three(0.0), &ZONES, &SET);
        // t_entry: A −2, B −1, C 0; t_nom: A 8, B 9, C 10.
        // t_f: A 8; B max(9, 8 + 3) = 11 (other lane); C max(10, 11 + 3) = 14.
        let slots = q.schedule(&SET);
        assert_eq!(
            slots,
            vec![
                (
                    1,
                    Slot {
                        place: 0,
                        crossing_s: 8.0
                    }
                ),
                (
                    2,
                    Slot {
                        place: 1,
                        crossing_s: 11.0
                    }
                ),
                (
                    3,
                    Slot {
                        place: 2,
                        crossing_s: 14.0
                    }
                ),
            ]
        );
        // Same lane: C behind A directly is δ = 2 s apart.
        let mut same = MergeQueue::new();
        same.update(
            0.0,
            &[report(1, 0.0, 30.0, false), report(3, 0.0, 0.0, false)],
            &ZONES,
            &SET,
        );
        assert_eq!(same.slot_of(3, &SET).map(|s| s.crossing_s), Some(10.0));
        let mut close = MergeQueue::new();
        close.update(
            0.0,
            &[report(1, 0.0, 30.0, false), report(3, 0.0, 15.0, false)],
            &ZONES,
            &SET,
        );
        // t_nom of car 3 would be 9: pushed to 8 + 2 = 10.
        assert_eq!(close.slot_of(3, &SET).map(|s| s.crossing_s), Some(10.0));
    }

    #[test]
    fn duplicates_and_late_messages_change_nothing() {
        let mut q = MergeQueue::new();
        q.update(0.0, &three(0.0), &ZONES, &SET);
        let before = q.clone();
        let mut twice = three(0.0);
        twice.extend(three(0.0));
        q.update(0.0, &twice, &ZONES, &SET);
        assert_eq!(q, before);
        // A newer report, then a late older one: the older one is ignored.
        q.update(0.1, &[report(1, 0.1, 31.5, false)], &ZONES, &SET);
        let after_new = q.clone();
        q.update(0.1, &[report(1, 0.05, 30.75, false)], &ZONES, &SET);
        assert_eq!(q, after_new);
    }

    #[test]
    fn a_lost_car_keeps_its_slot_until_the_timeout_then_is_dropped() {
        let mut q = MergeQueue::new();
        q.update(0.0, &three(0.0), &ZONES, &SET);
        // Car 2's messages are lost from t = 0.1 on; 1 and 3 are heard.
        let heard = |t: f64| {
            vec![
                report(1, t, 30.0 + 15.0 * t, false),
                report(3, t, 15.0 * t, false),
            ]
        };
        q.update(0.5, &heard(0.5), &ZONES, &SET);
        // Within the timeout: car 3 still waits behind car 2's slot (14 s).
        assert_eq!(q.slot_of(2, &SET).map(|s| s.crossing_s), Some(11.0));
        assert_eq!(q.slot_of(3, &SET).map(|s| s.crossing_s), Some(14.0));
        q.update(1.0, &heard(1.0), &ZONES, &SET);
        assert!(q.slot_of(2, &SET).is_some(), "1.0 s after: still kept");
        q.update(1.1, &heard(1.1), &ZONES, &SET);
        // Past the timeout: car 2 is dropped and car 3 follows car 1 directly (same lane).
        assert_eq!(q.slot_of(2, &SET), None);
        assert_eq!(q.slot_of(3, &SET).map(|s| s.crossing_s), Some(10.0));
        // Heard again: it rejoins with values latched from the new report (at 1.2 s, 33 m
        // ⇒ t_entry = −1 s as before: the order is unchanged).
        q.update(1.2, &[report(2, 1.2, 33.0, true)], &ZONES, &SET);
        assert_eq!(q.slot_of(2, &SET).map(|s| s.place), Some(1));
    }

    #[test]
    fn a_departed_car_anchors_the_next_slot() {
        let mut q = MergeQueue::new();
        q.update(0.0, &three(0.0), &ZONES, &SET);
        // Car 1 reaches the merging zone at 8.0 s and leaves at its end.
        let moved = [
            report(1, 8.0, 150.0, false),
            report(2, 8.0, 135.0, true),
            report(3, 8.0, 120.0, false),
        ];
        q.update(8.0, &moved, &ZONES, &SET);
        assert_eq!(q.members()[&1].arrival_s, Some(8.0));
        q.update(
            8.1,
            &[
                report(1, 8.1, 250.0, false),
                report(2, 8.1, 136.5, true),
                report(3, 8.1, 121.5, false),
            ],
            &ZONES,
            &SET,
        );
        assert!(!q.members().contains_key(&1));
        // Car 2 still waits δ_side behind car 1's arrival.
        assert_eq!(q.slot_of(2, &SET).map(|s| s.crossing_s), Some(11.0));
    }
}
