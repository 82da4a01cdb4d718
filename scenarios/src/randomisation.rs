//! The `[randomise]` table of a scenario: which nominal values a Monte-Carlo sweep perturbs, and
//! how.
//!
//! ```toml
//! [randomise]
//! mu = { uniform = [-0.1, 0.1] }            # sim.mu + U[-0.1, 0.1]
//! v2v_latency_s = { uniform = [0.0, 0.05] } # sim.v2v.latency_s + ...
//!
//! [randomise.every_vehicle]                  # applied to each vehicle, independent draws
//! cruise_speed_mps = { uniform = [-1.0, 1.0] }
//!
//! [randomise.vehicles.obstacle]              # one vehicle; overrides every_vehicle per key
//! x_m = { uniform = [-3.0, 3.0] }
//! ```
//!
//! Every entry is an offset added to the nominal value (so a scenario reads as "nominal ± spread",
//! and its nominal run is the centre of the sweep). `cruise_speed_mps` adds one draw to both the
//! initial and the target speed: a driver who cruises 1 m/s faster, rather than one who starts
//! faster and then returns to the nominal target; it adds to `speed_mps` / `target_speed_mps`
//! offsets if both are given.
//!
//! Streams: each randomised value has its own SplitMix64 stream, seeded with
//! `derive(derive(seed, 2), fnv1a64(key))` where `key` is e.g. `sim.mu` or
//! `vehicles.obstacle.x_m`. Stream 1 of the run seed is the World's V2V stream; 2 is this one.
//! So the draw of one value does not depend on which other values are randomised, nor on their
//! order in the file.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use sim::config::{SimConfig, VehicleSpec};
use sim::rng::SplitMix64;

use crate::distribution::Distribution;

/// Stream index (under the run seed) from which the scenario instance is drawn.
pub const INSTANCE_STREAM: u64 = 2;

/// Randomisation of the scenario-wide values.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Randomisation {
    /// Offset of `sim.mu`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu: Option<Distribution>,
    /// Offset of `sim.v2v.latency_s` (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v2v_latency_s: Option<Distribution>,
    /// Offset of `sim.v2v.drop_probability`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v2v_drop_probability: Option<Distribution>,
    /// Applied to every vehicle (independent draws per vehicle).
    #[serde(skip_serializing_if = "VehicleRandomisation::is_empty")]
    pub every_vehicle: VehicleRandomisation,
    /// Per vehicle name; a key given here replaces the same key of `every_vehicle`.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub vehicles: BTreeMap<String, VehicleRandomisation>,
}

/// Randomisation of one vehicle's values.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleRandomisation {
    /// Offset of the initial position (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x_m: Option<Distribution>,
    /// Offset of the lateral offset from the lane centre (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_offset_m: Option<Distribution>,
    /// Offset of the initial speed only (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_mps: Option<Distribution>,
    /// Offset of the target speed only (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_speed_mps: Option<Distribution>,
    /// One offset added to both the initial and the target speed (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cruise_speed_mps: Option<Distribution>,
}

/// The randomised vehicle fields, in a fixed order: (key, accessor).
type VehicleField = (
    &'static str,
    fn(&VehicleRandomisation) -> &Option<Distribution>,
);

const VEHICLE_FIELDS: [VehicleField; 5] = [
    ("x_m", |r| &r.x_m),
    ("y_offset_m", |r| &r.y_offset_m),
    ("speed_mps", |r| &r.speed_mps),
    ("target_speed_mps", |r| &r.target_speed_mps),
    ("cruise_speed_mps", |r| &r.cruise_speed_mps),
];

impl VehicleRandomisation {
    /// True when nothing is randomised.
    pub(crate) fn is_empty(&self) -> bool {
        VEHICLE_FIELDS.iter().all(|(_, get)| get(self).is_none())
    }
}

/// A randomisation entry that is wrong, with the path of its key (`randomise.vehicles.x.x_m`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RandomisationIssue {
    /// Dotted TOML path of the entry.
    pub path: Vec<String>,
    /// What is wrong.
    pub message: String,
}

/// How far one vehicle can be moved: offset bounds per target field, the resolved distributions.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct VehicleOffsetBounds {
    /// Offset bounds of `x_m`.
    pub x_m: [f64; 2],
    /// Offset bounds of `y_offset_m`.
    pub y_offset_m: [f64; 2],
    /// Offset bounds of `speed_mps` (including `cruise_speed_mps`).
    pub speed_mps: [f64; 2],
    /// Offset bounds of `target_speed_mps` (including `cruise_speed_mps`).
    pub target_speed_mps: [f64; 2],
}

impl Randomisation {
    /// True when nothing is randomised.
    pub fn is_empty(&self) -> bool {
        self == &Randomisation::default()
    }

    /// The distribution of vehicle `name`'s `key`: its own entry, else `every_vehicle`'s.
    fn vehicle_entry(&self, name: &str, field: usize) -> Option<(&Distribution, Vec<String>)> {
        let (key, get) = VEHICLE_FIELDS[field];
        if let Some(d) = self.vehicles.get(name).and_then(|r| get(r).as_ref()) {
            return Some((d, path(&["randomise", "vehicles", name, key])));
        }
        get(&self.every_vehicle)
            .as_ref()
            .map(|d| (d, path(&["randomise", "every_vehicle", key])))
    }

    /// The TOML path of the entry that moves vehicle `name`'s `field` (for error locations).
    pub fn vehicle_entry_path(&self, name: &str, field: &str) -> Option<Vec<String>> {
        let direct = VEHICLE_FIELDS.iter().position(|(k, _)| *k == field);
        let cruise = VEHICLE_FIELDS
            .iter()
            .position(|(k, _)| *k == "cruise_speed_mps");
        let mut candidates = direct.into_iter().collect::<Vec<_>>();
        if field == "speed_mps" || field == "target_speed_mps" {
            candidates.extend(cruise);
        }
        candidates
            .into_iter()
            .find_map(|i| self.vehicle_entry(name, i).map(|(_, p)| p))
    }

    /// The TOML path of the entry that moves the scenario-wide value `sim_field` (`mu`,
    /// `v2v.latency_s`, `v2v.drop_probability`).
    pub fn sim_entry_path(&self, sim_field: &str) -> Option<Vec<String>> {
        self.sim_entries()
            .into_iter()
            .find(|(_, field, d)| *field == sim_field && d.is_some())
            .map(|(key, _, _)| path(&["randomise", key]))
    }

    fn sim_entries(&self) -> [(&'static str, &'static str, Option<&Distribution>); 3] {
        [
            ("mu", "mu", self.mu.as_ref()),
            (
                "v2v_latency_s",
                "v2v.latency_s",
                self.v2v_latency_s.as_ref(),
            ),
            (
                "v2v_drop_probability",
                "v2v.drop_probability",
                self.v2v_drop_probability.as_ref(),
            ),
        ]
    }

    /// Checks every entry on its own: valid parameters, existing vehicle names.
    pub(crate) fn check_entries(&self, vehicles: &[VehicleSpec]) -> Result<(), RandomisationIssue> {
        for (key, _, d) in self.sim_entries() {
            if let Some(d) = d {
                d.validate().map_err(|message| RandomisationIssue {
                    path: path(&["randomise", key]),
                    message,
                })?;
            }
        }
        let mut tables: Vec<(Vec<String>, &VehicleRandomisation)> =
            vec![(path(&["randomise", "every_vehicle"]), &self.every_vehicle)];
        for (name, r) in &self.vehicles {
            if !vehicles.iter().any(|v| &v.name == name) {
                return Err(RandomisationIssue {
                    path: path(&["randomise", "vehicles", name]),
                    message: format!(
                        "no vehicle named {name:?} (vehicles: {})",
                        vehicles
                            .iter()
                            .map(|v| v.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            }
            tables.push((path(&["randomise", "vehicles", name]), r));
        }
        for (table_path, r) in tables {
            for (key, get) in VEHICLE_FIELDS {
                if let Some(d) = get(r) {
                    d.validate().map_err(|message| {
                        let mut p = table_path.clone();
                        p.push(key.to_string());
                        RandomisationIssue { path: p, message }
                    })?;
                }
            }
        }
        Ok(())
    }

    /// Offset bounds of every randomised value of vehicle `name`.
    pub(crate) fn vehicle_bounds(&self, name: &str) -> VehicleOffsetBounds {
        let bounds = |field: usize| {
            self.vehicle_entry(name, field)
                .map(|(d, _)| d.offset_bounds())
                .unwrap_or([0.0, 0.0])
        };
        let cruise = bounds(4);
        let add = |a: [f64; 2], b: [f64; 2]| [a[0] + b[0], a[1] + b[1]];
        VehicleOffsetBounds {
            x_m: bounds(0),
            y_offset_m: bounds(1),
            speed_mps: add(bounds(2), cruise),
            target_speed_mps: add(bounds(3), cruise),
        }
    }

    /// The scenario at one corner of the randomisation box: every randomised value at the lower
    /// (`upper = false`) or upper end of its range. The validity checks of a scenario are box
    /// constraints on these values, so checking both corners checks every possible instance.
    pub fn corner(
        &self,
        sim: &SimConfig,
        vehicles: &[VehicleSpec],
        upper: bool,
    ) -> (SimConfig, Vec<VehicleSpec>) {
        let end = |b: [f64; 2]| if upper { b[1] } else { b[0] };
        let mut sim = sim.clone();
        let [mu, lat, drop] = self
            .sim_entries()
            .map(|(_, _, d)| d.map(Distribution::offset_bounds));
        sim.mu += mu.map(end).unwrap_or(0.0);
        sim.v2v.latency_s += lat.map(end).unwrap_or(0.0);
        sim.v2v.drop_probability += drop.map(end).unwrap_or(0.0);
        let vehicles = vehicles
            .iter()
            .map(|v| {
                let b = self.vehicle_bounds(&v.name);
                let mut v = v.clone();
                v.x_m += end(b.x_m);
                v.y_offset_m += end(b.y_offset_m);
                v.speed_mps += end(b.speed_mps);
                v.target_speed_mps += end(b.target_speed_mps);
                v
            })
            .collect();
        (sim, vehicles)
    }

    /// Draws one instance of (`sim`, `vehicles`) for `seed` (see the module doc for the streams).
    pub fn draw(
        &self,
        sim: &SimConfig,
        vehicles: &[VehicleSpec],
        seed: u64,
    ) -> (SimConfig, Vec<VehicleSpec>) {
        let base = SplitMix64::derive(seed, INSTANCE_STREAM);
        let offset = |key: &str, d: Option<&Distribution>| {
            d.map(|d| d.sample_offset(&mut SplitMix64::new(SplitMix64::derive(base, fnv1a64(key)))))
                .unwrap_or(0.0)
        };
        let mut sim = sim.clone();
        sim.mu += offset("sim.mu", self.mu.as_ref());
        sim.v2v.latency_s += offset("sim.v2v.latency_s", self.v2v_latency_s.as_ref());
        sim.v2v.drop_probability += offset(
            "sim.v2v.drop_probability",
            self.v2v_drop_probability.as_ref(),
        );
        let vehicles = vehicles
            .iter()
            .map(|v| {
                let mut v = v.clone();
                let mut draws = [0.0; 5];
                for (i, draw) in draws.iter_mut().enumerate() {
                    let key = format!("vehicles.{}.{}", v.name, VEHICLE_FIELDS[i].0);
                    *draw = offset(&key, self.vehicle_entry(&v.name, i).map(|(d, _)| d));
                }
                let [x, y, speed, target, cruise] = draws;
                v.x_m += x;
                v.y_offset_m += y;
                v.speed_mps += speed + cruise;
                v.target_speed_mps += target + cruise;
                v
            })
            .collect();
        (sim, vehicles)
    }
}

fn path(parts: &[&str]) -> Vec<String> {
    parts.iter().map(|p| p.to_string()).collect()
}

/// 64-bit FNV-1a hash (Fowler, Noll & Vo): a fixed, documented function of the bytes.
pub fn fnv1a64(text: &str) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for byte in text.bytes() {
        hash ^= u64::from(byte);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // From the FNV reference test suite (Landon Curt Noll, isthe.com/chongo/tech/comp/fnv).
        assert_eq!(fnv1a64(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64("a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64("foobar"), 0x8594_4171_f739_67e8);
    }
}
