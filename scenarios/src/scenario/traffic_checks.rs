//! A scenario's `[traffic]` streams (`crate::traffic`): their checks, their nominal vehicles,
//! and the scenario written out without the vehicles they generate.

use serde::Serializer;
use serde::ser::SerializeStruct;

use super::*;
use crate::traffic::{self, TrafficIssue};

impl Scenario {
    /// The vehicles the file lists (`[[vehicles]]`), without those `[traffic]` generated.
    pub fn fixed_vehicles(&self) -> &[VehicleSpec] {
        let fixed = self.vehicles.len().saturating_sub(self.generated_vehicles);
        &self.vehicles[..fixed]
    }

    /// The instance a run uses (the nominal one without a seed, else
    /// [`Scenario::instantiate`]) with every vehicle listed and no `[traffic]` or `[randomise]`
    /// left: what `merge_sim scenario expand` prints.
    pub fn expanded(&self, seed: Option<u64>) -> Scenario {
        match seed {
            Some(seed) => self.instantiate(seed),
            None => Scenario {
                traffic: Traffic::new(),
                generated_vehicles: 0,
                randomise: Randomisation::default(),
                ..self.clone()
            },
        }
    }

    /// Checks the `[traffic]` streams on their own and against the listed vehicles, then
    /// appends the nominal instance's vehicles (`text`: the TOML, for the lines).
    pub(crate) fn attach_traffic(&mut self, origin: &str, text: &str) -> Result<(), ScenarioError> {
        let error = |path: Vec<String>, message: String| {
            let field = path.join(".");
            ScenarioError::Invalid {
                origin: origin.to_string(),
                line: Line(line_of(text, &path)),
                message: format!("{field}: {message}"),
                field: Some(field),
            }
        };
        let key_path = |stream: &str, key: &str| {
            let mut path = vec!["traffic".to_string(), stream.to_string()];
            if !key.is_empty() {
                path.push(key.to_string());
            }
            path
        };
        let mut densest_total = self.fixed_vehicles().len();
        for (name, stream) in &self.traffic {
            stream
                .validate(name)
                .map_err(|TrafficIssue { key, message }| error(key_path(name, key), message))?;
            // The densest instance's count, before generating it (equation (2) at h₀).
            let per_lane =
                (stream.front_x_m - stream.rear_x_m) / (stream.speed_mps * stream.min_headway_s);
            let count = (per_lane.floor() + 1.0) * stream.lanes.len() as f64;
            if count + densest_total as f64 > sim::config::MAX_VEHICLES as f64 {
                return Err(error(
                    key_path(name, "min_headway_s"),
                    format!(
                        "with every headway at min_headway_s = {} s, the window [{}, {}] m at {} \
                         m/s holds up to {count} vehicles, {} with the vehicles before it: more \
                         than the {} a scenario may have (shorten the window or raise \
                         min_headway_s)",
                        stream.min_headway_s,
                        stream.rear_x_m,
                        stream.front_x_m,
                        stream.speed_mps,
                        count as usize + densest_total,
                        sim::config::MAX_VEHICLES
                    ),
                ));
            }
            densest_total += count as usize;
            for (index, v) in self.vehicles.iter().enumerate() {
                let x_path = vec!["vehicles".to_string(), index.to_string(), "x_m".into()];
                if v.name.starts_with(&format!("{name}_")) {
                    return Err(error(
                        vec!["vehicles".to_string(), index.to_string(), "name".into()],
                        format!(
                            "vehicle name {:?}: names starting with \"{name}_\" are those \
                             [traffic.{name}] generates",
                            v.name
                        ),
                    ));
                }
                let margin_m = stream.speed_mps * stream.min_headway_s;
                let in_window =
                    (stream.rear_x_m - margin_m..=stream.front_x_m + margin_m).contains(&v.x_m);
                if in_window && stream.lanes.iter().any(|l| traffic::same_lane(*l, v.lane)) {
                    return Err(error(
                        x_path,
                        format!(
                            "vehicle {} starts at x_m = {} in lane {}, inside the window of \
                             [traffic.{name}] widened by its smallest spacing, [{}, {}] m: \
                             its generated vehicles could overlap it",
                            v.name,
                            v.x_m,
                            traffic::lane_label(v.lane),
                            stream.rear_x_m - margin_m,
                            stream.front_x_m + margin_m
                        ),
                    ));
                }
            }
        }
        let generated = traffic::generate(&self.traffic, TrafficInstance::Nominal);
        self.generated_vehicles = generated.len();
        self.vehicles.extend(generated);
        Ok(())
    }

    /// Runs the scenario's checks on the densest instance of its `[traffic]` (every headway
    /// at `min_headway_s`): the most vehicles and the closest spacing any seed can draw, and
    /// both ends of every window, so that every instance is valid if it is.
    pub(super) fn check_densest_traffic(
        &self,
        origin: &str,
        text: Option<&str>,
    ) -> Result<(), ScenarioError> {
        if self.traffic.is_empty() {
            return Ok(());
        }
        let mut vehicles = self.fixed_vehicles().to_vec();
        vehicles.extend(traffic::generate(&self.traffic, TrafficInstance::Densest));
        let count = vehicles.len();
        let probe = Scenario {
            vehicles,
            traffic: Traffic::new(),
            generated_vehicles: 0,
            ..self.clone()
        };
        probe
            .check_values(origin, None)
            .map_err(|e| self.traffic_error(e, "densest", count, origin, text))
    }

    /// `e`, from checking an instance of `[traffic]` (`which`: `nominal` or `densest`, with
    /// `count` vehicles), as an error of the stream whose generated vehicle it names (the line
    /// of its table). Errors that name no generated vehicle pass unchanged, except for the
    /// densest instance, which only the `[traffic]` tables make (the first stream is named).
    pub(super) fn traffic_error(
        &self,
        e: ScenarioError,
        which: &str,
        count: usize,
        origin: &str,
        text: Option<&str>,
    ) -> ScenarioError {
        if self.traffic.is_empty() {
            return e;
        }
        let generated = |name: &str| {
            which == "densest"
                || self.vehicles[self.fixed_vehicles().len()..]
                    .iter()
                    .any(|v| v.name == name)
        };
        let named = match &e {
            ScenarioError::Invalid { field, .. } => field
                .as_deref()
                .and_then(|f| f.strip_prefix("vehicles["))
                .and_then(|f| f.split_once(']'))
                .map(|(name, _)| name.to_string()),
            _ => None,
        };
        let stream = match &named {
            Some(name) if generated(name) => traffic::stream_of(&self.traffic, name),
            _ if which == "densest" => None,
            _ => return e,
        }
        .or_else(|| self.traffic.keys().next().map(String::as_str))
        .unwrap_or_default()
        .to_string();
        let message = match e {
            ScenarioError::Invalid { message, .. } => message,
            other => other.to_string(),
        };
        let what = match which {
            "densest" => "every headway at min_headway_s",
            _ => "centre flows, mean headways",
        };
        let path = vec!["traffic".to_string(), stream.clone()];
        ScenarioError::Invalid {
            origin: origin.to_string(),
            line: Line(text.and_then(|t| line_of(t, &path))),
            field: Some(format!("traffic.{stream}")),
            message: format!(
                "traffic.{stream}: the {which} instance of [traffic] ({what}, {count} vehicles) \
                 is invalid: {message}"
            ),
        }
    }
}

/// The scenario as its file would say it: the listed `[[vehicles]]` and the `[traffic]`
/// tables, not the vehicles those generate (which reading the text back generates again).
impl Serialize for Scenario {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let fields =
            5 + usize::from(!self.traffic.is_empty()) + usize::from(!self.randomise.is_empty());
        let mut s = serializer.serialize_struct("Scenario", fields)?;
        s.serialize_field("name", &self.name)?;
        s.serialize_field("description", &self.description)?;
        s.serialize_field("params", &self.params)?;
        s.serialize_field("sim", &self.sim)?;
        s.serialize_field("vehicles", self.fixed_vehicles())?;
        if !self.traffic.is_empty() {
            s.serialize_field("traffic", &self.traffic)?;
        }
        if !self.randomise.is_empty() {
            s.serialize_field("randomise", &self.randomise)?;
        }
        s.end()
    }
}
