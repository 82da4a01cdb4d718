//! Who drives a vehicle (`driver = …` in a scenario's `[[vehicles]]`), and its TOML / JSON form:
//!
//! ```toml
//! driver = { planner = "pf-iso" }                                  # a registered planner
//! driver = { planner = "pf-iso", params = { waypoint_count = 16 } } # with its own parameters
//! driver = { prescribed = { path_planner = "pf-iso", speed_profile = [[0.0, 20.0]] } }
//! driver = "idm"                                                   # or "idm-mobil", "lane-keeping"
//! ```
//!
//! The `params` table may also be written under a `[vehicles.driver.params]` header.

use std::fmt;

use planner::speed_profile::SpeedProfile;
use serde::de::{self, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::planner_params::ParamsTable;

/// How a vehicle decides its path and speed (module doc for the file form).
#[derive(Clone, Debug, PartialEq)]
pub enum Driver {
    /// A planner by its registered name: `pf-cs`, `pf-sp`, `pf-sp-eq10`, `pf-iso`,
    /// `pf-iso-pred`, or a user's (`crate::registry`).
    Planner {
        /// The registered name.
        name: String,
        /// The vehicle's own planner parameters (`params = { … }`), overlaying the scenario's
        /// table of that planner key by key, read by the planner's schema
        /// (`crate::planner_params`).
        params: Option<ParamsTable>,
    },
    /// The path of a potential-field planner (`path_planner`), the speeds of a prescribed
    /// time → speed profile (`speed_profile = [[t_s, speed_mps], …]`, linear in between, held
    /// outside). Not changed by `--planner`. Tests whether a given speed profile (e.g. the
    /// paper's pre-braking) changes the winding, without the speed optimiser.
    Prescribed {
        /// Planner (registered name) whose path the vehicle follows.
        path_planner: String,
        /// The speeds.
        speed_profile: SpeedProfile,
    },
    /// No planner: holds its lane centre and target speed, blind to others (for deliberately
    /// unsafe tests).
    LaneKeeping,
    /// A human driver: Intelligent Driver Model car following (Treiber et al. 2000) with lane
    /// keeping; never changes lanes, never connected.
    Idm,
    /// A human driver who changes lanes: IDM car following with MOBIL lane changes (Kesting,
    /// Treiber & Helbing 2007; `crate::mobil`, parameters `[sim.mobil]`). A lane that ends is a
    /// standing obstacle at its end until MOBIL finds a gap. Never connected.
    IdmMobil,
}

impl Driver {
    /// The planner registered as `name`, with the scenario's parameters of that planner.
    pub fn planner(name: impl Into<String>) -> Self {
        Self::Planner {
            name: name.into(),
            params: None,
        }
    }

    /// The registered planner's name, if the vehicle is driven by one (`Planner`).
    pub fn planner_name(&self) -> Option<&str> {
        match self {
            Self::Planner { name, .. } => Some(name),
            _ => None,
        }
    }

    /// The driver's class in the traffic figures (`crate::traffic_metrics`): the planner's
    /// name (`planner_override` replacing it, as `--planner` does), or `prescribed`,
    /// `lane-keeping`, `idm`, `idm-mobil`.
    pub fn class(&self, planner_override: Option<&str>) -> String {
        match self {
            Self::Planner { name, .. } => planner_override.unwrap_or(name).to_string(),
            Self::Prescribed { .. } => "prescribed".to_string(),
            Self::LaneKeeping => "lane-keeping".to_string(),
            Self::Idm => "idm".to_string(),
            Self::IdmMobil => "idm-mobil".to_string(),
        }
    }

    /// The vehicle's own planner parameters, if any.
    pub fn params(&self) -> Option<&ParamsTable> {
        match self {
            Self::Planner { params, .. } => params.as_ref(),
            _ => None,
        }
    }
}

/// The names a driver is written with.
const FORMS: &[&str] = &["planner", "prescribed", "lane-keeping", "idm", "idm-mobil"];
/// The keys of a driver table.
const KEYS: &[&str] = &["planner", "params", "prescribed"];

/// `prescribed = { … }`, as read.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PrescribedForm {
    path_planner: String,
    speed_profile: SpeedProfile,
}

/// `prescribed = { … }`, as written (borrowing the driver's fields).
#[derive(Serialize)]
struct PrescribedRef<'a> {
    path_planner: &'a str,
    speed_profile: &'a SpeedProfile,
}

impl Serialize for Driver {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::Planner { name, params } => {
                let mut map = serializer.serialize_map(Some(1 + usize::from(params.is_some())))?;
                map.serialize_entry("planner", name)?;
                if let Some(params) = params {
                    map.serialize_entry("params", params)?;
                }
                map.end()
            }
            Self::Prescribed {
                path_planner,
                speed_profile,
            } => {
                let mut map = serializer.serialize_map(Some(1))?;
                map.serialize_entry(
                    "prescribed",
                    &PrescribedRef {
                        path_planner,
                        speed_profile,
                    },
                )?;
                map.end()
            }
            Self::LaneKeeping => serializer.serialize_str("lane-keeping"),
            Self::Idm => serializer.serialize_str("idm"),
            Self::IdmMobil => serializer.serialize_str("idm-mobil"),
        }
    }
}

impl<'de> Deserialize<'de> for Driver {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(DriverVisitor)
    }
}

struct DriverVisitor;

impl<'de> Visitor<'de> for DriverVisitor {
    type Value = Driver;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(
            "a driver: { planner = \"NAME\" } (optionally with params = { … }), \
             { prescribed = { path_planner, speed_profile } }, \"lane-keeping\", \"idm\" or \
             \"idm-mobil\"",
        )
    }

    fn visit_str<E: de::Error>(self, value: &str) -> Result<Driver, E> {
        match value {
            "lane-keeping" => Ok(Driver::LaneKeeping),
            "idm" => Ok(Driver::Idm),
            "idm-mobil" => Ok(Driver::IdmMobil),
            other => Err(E::unknown_variant(other, FORMS)),
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Driver, A::Error> {
        let mut name: Option<String> = None;
        let mut params: Option<ParamsTable> = None;
        let mut prescribed: Option<PrescribedForm> = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "planner" if name.is_none() => name = Some(map.next_value()?),
                "params" if params.is_none() => params = Some(map.next_value()?),
                "prescribed" if prescribed.is_none() => prescribed = Some(map.next_value()?),
                "planner" => return Err(de::Error::duplicate_field("planner")),
                "params" => return Err(de::Error::duplicate_field("params")),
                "prescribed" => return Err(de::Error::duplicate_field("prescribed")),
                "lane-keeping" | "idm" | "idm-mobil" => {
                    return Err(de::Error::custom(format!(
                        "write this driver as a string: driver = \"{key}\""
                    )));
                }
                other => return Err(de::Error::unknown_field(other, KEYS)),
            }
        }
        match (name, params, prescribed) {
            (Some(name), params, None) => Ok(Driver::Planner { name, params }),
            (None, None, Some(p)) => Ok(Driver::Prescribed {
                path_planner: p.path_planner,
                speed_profile: p.speed_profile,
            }),
            (None, Some(_), _) => Err(de::Error::custom(
                "params go with a planner: driver = { planner = \"NAME\", params = { … } }",
            )),
            (Some(_), _, Some(_)) => Err(de::Error::custom(
                "a driver is either a planner or prescribed, not both",
            )),
            (None, None, None) => Err(de::Error::custom(
                "an empty driver: write driver = { planner = \"NAME\" }, a prescribed driver, \
                 \"lane-keeping\", \"idm\" or \"idm-mobil\"",
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Serialize, Deserialize, PartialEq)]
    struct Holder {
        driver: Driver,
    }

    fn read(text: &str) -> Result<Driver, String> {
        toml::from_str::<Holder>(text)
            .map(|h| h.driver)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn every_form_reads_and_writes_back_the_same() {
        for text in [
            "driver = { planner = \"pf-iso\" }",
            "driver = { planner = \"pf-iso\", params = { waypoint_count = 16 } }",
            "driver = { prescribed = { path_planner = \"pf-iso\", speed_profile = [[0.0, 20.0]] } }",
            "driver = \"lane-keeping\"",
            "driver = \"idm\"",
            "driver = \"idm-mobil\"",
        ] {
            let driver = read(text).unwrap();
            let written = toml::to_string(&Holder {
                driver: driver.clone(),
            })
            .unwrap();
            assert_eq!(read(&written).unwrap(), driver, "{text} → {written}");
            let json = serde_json::to_string(&driver).unwrap();
            assert_eq!(serde_json::from_str::<Driver>(&json).unwrap(), driver);
        }
        let with_params = read("driver = { planner = \"x\", params = { a = 1 } }").unwrap();
        assert_eq!(with_params.planner_name(), Some("x"));
        assert_eq!(
            with_params.params().and_then(|p| p.get("a")),
            Some(&toml::Value::Integer(1))
        );
        // The header form.
        let header = read("[driver]\nplanner = \"x\"\n[driver.params]\na = 1\n").unwrap();
        assert_eq!(header, with_params);
    }

    #[test]
    fn a_bad_driver_is_refused_with_what_is_wrong() {
        let cases = [
            ("driver = \"pf-iso\"", "unknown variant `pf-iso`"),
            (
                "driver = { planner = \"x\", parms = {} }",
                "unknown field `parms`",
            ),
            (
                "driver = { params = { a = 1 } }",
                "params go with a planner",
            ),
            (
                "driver = { planner = \"x\", prescribed = { path_planner = \"x\", speed_profile = [] } }",
                "not both",
            ),
            ("driver = {}", "an empty driver"),
            ("driver = { planner = \"x\", params = 3 }", "params"),
        ];
        for (text, words) in cases {
            let e = read(text).unwrap_err();
            assert!(e.contains(words), "{text}: {e}");
        }
    }
}
