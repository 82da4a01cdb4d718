//! Routing along a road of lanes: the shortest route by length from a vehicle's lane to a goal,
//! through successors and same-direction neighbours (Dijkstra).
//!
//! The cost of a route is the length of every lane it enters (the start lane's remainder
//! beyond the vehicle counts as nothing: every route leaves it), so a lane change costs the
//! length of the lane changed into, as a successor does. Ties go to the route found first with
//! lanes taken in id order (deterministic).

use std::cmp::Ordering;
use std::collections::{BTreeMap, BinaryHeap};

use mergesim_types::lanes::{LaneId, LaneRoad};

#[derive(Clone, Copy, PartialEq)]
struct Entry {
    cost_m: f64,
    lane: LaneId,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on cost, then on the lane id.
        other
            .cost_m
            .total_cmp(&self.cost_m)
            .then_with(|| other.lane.0.cmp(&self.lane.0))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The lanes reachable in one move from `lane`: its successors, then its same-direction left and
/// right neighbours (a road of lanes links same-direction neighbours only).
pub(crate) fn next_lanes(lanes: &LaneRoad, lane: LaneId) -> Vec<LaneId> {
    let Some(l) = lanes.lane(lane) else {
        return Vec::new();
    };
    let mut next: Vec<LaneId> = l.successors().to_vec();
    next.extend(l.left_neighbour());
    next.extend(l.right_neighbour());
    next
}

/// The shortest route (module doc) from `start` to any lane of `goals`, as the lanes in driving
/// order (`start` first, a goal lane last); `None` if no goal lane is reachable. A start lane
/// that is a goal lane is a route of one lane.
pub fn shortest_route(lanes: &LaneRoad, start: LaneId, goals: &[LaneId]) -> Option<Vec<LaneId>> {
    lanes.lane(start)?;
    let mut best: BTreeMap<LaneId, f64> = BTreeMap::new();
    let mut previous: BTreeMap<LaneId, LaneId> = BTreeMap::new();
    let mut heap = BinaryHeap::new();
    best.insert(start, 0.0);
    heap.push(Entry {
        cost_m: 0.0,
        lane: start,
    });
    while let Some(Entry { cost_m, lane }) = heap.pop() {
        if best.get(&lane).is_some_and(|&b| cost_m > b) {
            continue;
        }
        if goals.contains(&lane) {
            let mut route = vec![lane];
            let mut at = lane;
            while let Some(&p) = previous.get(&at) {
                route.push(p);
                at = p;
            }
            route.reverse();
            return Some(route);
        }
        for next in next_lanes(lanes, lane) {
            let Some(n) = lanes.lane(next) else {
                continue;
            };
            let cost = cost_m + n.length_m();
            if best.get(&next).is_none_or(|&b| cost < b) {
                best.insert(next, cost);
                previous.insert(next, lane);
                heap.push(Entry {
                    cost_m: cost,
                    lane: next,
                });
            }
        }
    }
    None
}

/// The lanes a goal region touches: every lane with a point of its centreline (sampled every
/// metre and at its ends) for which `inside` holds.
pub fn lanes_touching(lanes: &LaneRoad, inside: impl Fn([f64; 2]) -> bool) -> Vec<LaneId> {
    lanes
        .lanes()
        .iter()
        .filter(|l| {
            let n = (l.length_m().ceil() as usize).clamp(1, 100_000);
            (0..=n).any(|k| inside(l.point(l.length_m() * k as f64 / n as f64, 0.0)))
        })
        .map(|l| l.id())
        .collect()
}

#[cfg(test)]
#[path = "route_tests.rs"]
mod tests;
