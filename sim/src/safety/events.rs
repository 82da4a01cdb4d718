//! What the safety checks report: collision and road-edge contact events, per-pair figures, the
//! run's summary and each checked instant's report.

use mergesim_types::VehicleId;
use serde::{Deserialize, Serialize};

/// Which road edge: the drivable area's outer edges seen in the direction of travel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadEdge {
    /// A left-hand outer edge (the road on its right); on the merge road the straight upper
    /// edge, Y = Y_u.
    Upper,
    /// A right-hand outer edge (the road on its left), closed lane ends included; on the merge
    /// road the piecewise lower edge of Eq. 3, including the merge taper.
    Lower,
}

/// Start of a collision episode between two vehicles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CollisionEvent {
    /// The checked instant at which the boxes were first found intersecting (s).
    pub t_s: f64,
    /// Smaller id of the pair.
    pub id_a: VehicleId,
    /// Larger id of the pair.
    pub id_b: VehicleId,
    /// Time of first contact between the previous checked instant and `t_s`, from the TTC at
    /// the previous instant (exact for constant velocities); `None` if the pair was already
    /// intersecting or not closing then.
    pub t_contact_estimate_s: Option<f64>,
    /// Relative speed |v_b − v_a| at `t_s` (m/s).
    pub relative_speed_mps: f64,
    /// A recorded vehicle ran into a simulated one from behind (`recorded_pairs` module doc
    /// of the safety monitor): not the planner's collision.
    #[serde(default)]
    pub caused_by_replay: bool,
}

impl CollisionEvent {
    /// Whether vehicle `id` is one of the two.
    pub fn involves(&self, id: VehicleId) -> bool {
        self.id_a == id || self.id_b == id
    }
}

/// Start of an episode of a vehicle touching or crossing a road edge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EdgeContactEvent {
    /// The checked instant (s).
    pub t_s: f64,
    /// The vehicle.
    pub id: VehicleId,
    /// Which edge.
    pub edge: RoadEdge,
}

/// Safety figures of one pair of vehicles over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairSafety {
    /// Smaller id.
    pub id_a: VehicleId,
    /// Larger id.
    pub id_b: VehicleId,
    /// Minimum exact gap between the boxes over the instants the pair was followed (m): its
    /// minimum over the run whenever that is below `pair_range_m`; 0 when they touched.
    pub min_gap_m: f64,
    /// When the minimum gap was first reached (s).
    pub t_min_gap_s: f64,
    /// Minimum TTC (s); `None` if never closing within the horizon.
    pub min_ttc_s: Option<f64>,
    /// When the minimum TTC was first reached (s).
    pub t_min_ttc_s: Option<f64>,
    /// Time with TTC below the threshold (s).
    pub tet_s: f64,
    /// Number of collision episodes.
    pub collisions: u32,
    /// Near miss: min TTC or min gap below its threshold, without a collision.
    pub near_miss: bool,
}

/// The safety outcome of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SafetySummary {
    /// Every collision episode, in time order (pairs in id order within an instant), those
    /// caused by the replay of recorded traffic included.
    pub collisions: Vec<CollisionEvent>,
    /// How many of [`Self::collisions`] a recorded vehicle caused by running into a simulated
    /// one from behind (`CollisionEvent::caused_by_replay`); the planners' own are the others.
    #[serde(default)]
    pub collisions_caused_by_replay: u32,
    /// Minimum exact gap between a simulated and a recorded vehicle's boxes (m), as
    /// [`Self::min_gap_m`] over those pairs only; `None` without recorded traffic in range.
    #[serde(default)]
    pub min_gap_to_recorded_m: Option<f64>,
    /// Minimum TTC between a simulated and a recorded vehicle (s); `None` if no such pair was
    /// ever closing within the horizon.
    #[serde(default)]
    pub min_ttc_to_recorded_s: Option<f64>,
    /// Minimum exact gap between any two boxes (m): the smallest of [`Self::pairs`], exact
    /// whenever it is below `pair_range_m`; `None` when no pair was ever followed (fewer than
    /// two vehicles, or none ever within that range).
    pub min_gap_m: Option<f64>,
    /// When `min_gap_m` was first reached (s).
    pub t_min_gap_s: Option<f64>,
    /// Minimum TTC over all pairs and instants (s).
    pub min_ttc_s: Option<f64>,
    /// When `min_ttc_s` was first reached (s).
    pub t_min_ttc_s: Option<f64>,
    /// Near miss: (min TTC < threshold or min gap < gap threshold) and no collision.
    pub near_miss: bool,
    /// Time during which at least one pair had TTC below the threshold (s).
    pub tet_s: f64,
    /// Per vehicle that was ever exposed, in id order: `(id, time during which at least one of
    /// its pairs had TTC below the threshold (s))`. Summed over vehicles this is the TET of
    /// Minderhoud & Bovy (2001), which counts each exposed vehicle's time.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vehicle_tet_s: Vec<(VehicleId, f64)>,
    /// Every road-edge contact episode, in time order.
    pub edge_contacts: Vec<EdgeContactEvent>,
    /// Per pair that was ever followed (`SafetyMonitor`'s module doc), in id order.
    pub pairs: Vec<PairSafety>,
    /// Number of checked instants.
    pub checked_instants: u64,
    /// Sum of the `dt_s` of the checked instants (s).
    pub checked_duration_s: f64,
    /// Shape casts that stopped without converging (their TTC is parry's conservative value).
    pub ttc_not_converged: u64,
}

impl SafetySummary {
    /// The collision episodes that are not caused by the replay of recorded traffic: the
    /// simulated vehicles' own (vehicle–vehicle only; road-edge contacts are apart).
    pub fn own_collisions(&self) -> usize {
        self.collisions.len()
            - (self.collisions_caused_by_replay as usize).min(self.collisions.len())
    }
}

/// What one pair looked like at the last checked instant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairInstant {
    /// Smaller id.
    pub id_a: VehicleId,
    /// Larger id.
    pub id_b: VehicleId,
    /// Whether the boxes intersect.
    pub intersecting: bool,
    /// Gap between the boxes (m): exact, or a lower bound when `gap_is_lower_bound`.
    pub gap_m: f64,
    /// True when the pair was far enough apart that only the bounding-circle bound was computed.
    pub gap_is_lower_bound: bool,
    /// TTC (s), `None` if not touching within the horizon at constant velocity.
    pub ttc_s: Option<f64>,
}

/// The result of one [`SafetyMonitor::check`](super::SafetyMonitor::check).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SafetyStepReport {
    /// The instant (s).
    pub t_s: f64,
    /// Every pair followed at this instant, in id order.
    pub pairs: Vec<PairInstant>,
    /// Collision episodes that started at this instant.
    pub new_collisions: Vec<CollisionEvent>,
    /// Edge contact episodes that started at this instant.
    pub new_edge_contacts: Vec<EdgeContactEvent>,
    /// Smallest TTC at this instant.
    pub min_ttc_s: Option<f64>,
}
