//! The endpoints a study plan may name: figures of a run's JSON summary (`merge_sim run
//! --json`), per vehicle (`<vehicle>.<figure>`, the paper's figures included) or of the run
//! (`min_gap_m`, `min_ttc_s`, `tet_s`, and the traffic figures of [`RUN_FIGURES`]), each with
//! the unit its name carries.

use serde_json::Value;
use sim::metrics::{VehicleMetrics, VehicleMetricsSummary};

use crate::summary::RunSummary;

/// Run-level figures a plan may name (whole run: safety and traffic figures, not motion
/// states). The traffic figures are `sim::traffic_metrics`'s: `throughput_vph` through the
/// merge, `mean_delay_s` against free flow, `unmerged_vehicles` (vehicles of an ending lane
/// that did not merge before it ended) and the safety shield's interventions.
pub const RUN_FIGURES: [&str; 7] = [
    "min_gap_m",
    "min_ttc_s",
    "tet_s",
    "throughput_vph",
    "mean_delay_s",
    "unmerged_vehicles",
    "shield_interventions",
];

/// Per-vehicle figures that are not endpoints (bookkeeping, not outcomes).
const NOT_ENDPOINTS: [&str; 3] = [
    "samples",
    "duration_s",
    // A table ({t_s, x_m}) or null, not a number.
    "divider_crossing",
];

/// The per-vehicle figures an endpoint may name, sorted: every numeric field of a vehicle's
/// summary and of its `paper_metrics` (read off a summary, so new figures join by themselves).
pub fn vehicle_figures() -> Vec<String> {
    let Ok(lanes) = mergesim_types::MergeRoad::default().lane_road() else {
        return Vec::new();
    };
    let template = VehicleMetrics::new("v")
        .with_paper_metrics(std::sync::Arc::new(lanes), 20.0)
        .summary();
    let mut names = Vec::new();
    let Ok(Value::Object(map)) = serde_json::to_value(&template) else {
        return names;
    };
    let numeric = |v: &Value| v.is_number() || v.is_null();
    for (key, value) in &map {
        if key == "paper_metrics" {
            if let Value::Object(paper) = value {
                names.extend(
                    paper
                        .iter()
                        .filter(|(_, v)| numeric(v))
                        .map(|(k, _)| k.clone()),
                );
            }
        } else if numeric(value) && key != "pre_contact" {
            names.push(key.clone());
        }
    }
    names.retain(|n| !NOT_ENDPOINTS.contains(&n.as_str()));
    names.sort();
    names.dedup();
    names
}

/// The SI unit a figure's name carries (`…_radps` → `rad/s`); `1` for counts.
pub fn unit_of(figure: &str) -> &'static str {
    const SUFFIXES: [(&str, &str); 8] = [
        ("_vph", "veh/h"),
        ("_radps", "rad/s"),
        ("_rad", "rad"),
        ("_mps3", "m/s^3"),
        ("_mps2", "m/s^2"),
        ("_mps", "m/s"),
        ("_m", "m"),
        ("_s", "s"),
    ];
    SUFFIXES
        .iter()
        .find(|(suffix, _)| figure.ends_with(suffix))
        .map_or("1", |(_, unit)| unit)
}

/// A unit as written in a plan, in the canonical spelling of [`unit_of`] (`m/s²` → `m/s^2`,
/// `count` → `1`); `None` if it is not a unit an endpoint has.
pub fn canonical_unit(text: &str) -> Option<&'static str> {
    Some(match text.trim() {
        "rad/s" => "rad/s",
        "rad" => "rad",
        "m/s^3" | "m/s³" | "m/s3" => "m/s^3",
        "m/s^2" | "m/s²" | "m/s2" => "m/s^2",
        "m/s" => "m/s",
        "veh/h" | "vph" => "veh/h",
        "m" => "m",
        "s" => "s",
        "1" | "count" | "counts" => "1",
        _ => return None,
    })
}

/// An endpoint: a run-level figure or a figure of one vehicle.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct EndpointFigure {
    /// The name as the plan writes it (`obstacle.max_abs_yaw_rate_radps`, `min_gap_m`).
    pub name: String,
    /// The vehicle (`None`: a run-level figure).
    pub vehicle: Option<String>,
    /// The figure's field name.
    pub figure: String,
}

impl EndpointFigure {
    /// Parses `name` against the scenario's `vehicles`; the error says what is allowed.
    pub fn parse(name: &str, vehicles: &[String]) -> Result<Self, String> {
        if RUN_FIGURES.contains(&name) {
            return Ok(Self {
                name: name.into(),
                vehicle: None,
                figure: name.into(),
            });
        }
        let Some((vehicle, figure)) = name.split_once('.') else {
            return Err(format!(
                "unknown endpoint {name:?}: expected <vehicle>.<figure> (vehicles: {}) or a run \
                 figure ({})",
                vehicles.join(", "),
                RUN_FIGURES.join(", ")
            ));
        };
        if !vehicles.iter().any(|v| v == vehicle) {
            return Err(format!(
                "unknown endpoint {name:?}: no vehicle {vehicle:?} in the scenario (vehicles: {})",
                vehicles.join(", ")
            ));
        }
        let figures = vehicle_figures();
        if !figures.iter().any(|f| f == figure) {
            return Err(format!(
                "unknown endpoint {name:?}: {figure:?} is not a figure of a vehicle (figures: {})",
                figures.join(", ")
            ));
        }
        Ok(Self {
            name: name.into(),
            vehicle: Some(vehicle.into()),
            figure: figure.into(),
        })
    }

    /// Whether the figure is a motion state of a vehicle (measured before the first contact)
    /// rather than a run-level safety figure (whole run).
    pub fn is_motion_state(&self) -> bool {
        self.vehicle.is_some()
    }

    /// The unit of the figure.
    pub fn unit(&self) -> &'static str {
        unit_of(&self.figure)
    }

    /// (before the first contact, whole run) values of the figure in `summary`; `None` where
    /// the summary holds null (e.g. a minimum TTC of a run that never closed) or lacks it.
    pub fn values(&self, summary: &RunSummary) -> (Option<f64>, Option<f64>) {
        let Some(vehicle) = &self.vehicle else {
            let value = match self.figure.as_str() {
                "min_gap_m" => summary.min_gap_m,
                "min_ttc_s" => summary.min_ttc_s,
                "tet_s" => Some(summary.tet_s),
                "throughput_vph" => summary.traffic.throughput_vph,
                "mean_delay_s" => summary.traffic.mean_delay_s,
                "unmerged_vehicles" => Some(f64::from(
                    summary.traffic.merging
                        - summary
                            .traffic
                            .merged_before_lane_end
                            .min(summary.traffic.merging),
                )),
                "shield_interventions" => Some(summary.shield_interventions as f64),
                _ => None,
            };
            return (value, value);
        };
        let Some(v) = summary.vehicles.iter().find(|v| &v.id == vehicle) else {
            return (None, None);
        };
        (
            figure_of(v.before_first_contact(), &self.figure),
            figure_of(v, &self.figure),
        )
    }
}

/// A numeric field of a vehicle summary (or of its `paper_metrics`) by name.
fn figure_of(summary: &VehicleMetricsSummary, figure: &str) -> Option<f64> {
    let value = serde_json::to_value(summary).ok()?;
    value
        .get(figure)
        .or_else(|| value.get("paper_metrics").and_then(|p| p.get(figure)))
        .and_then(Value::as_f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_follow_the_names() {
        assert_eq!(unit_of("max_abs_yaw_rate_radps"), "rad/s");
        assert_eq!(unit_of("max_abs_sideslip_rad"), "rad");
        assert_eq!(unit_of("peak_abs_jerk_lat_mps3"), "m/s^3");
        assert_eq!(unit_of("rms_accel_long_mps2"), "m/s^2");
        assert_eq!(unit_of("min_speed_mps"), "m/s");
        assert_eq!(unit_of("path_length_m"), "m");
        assert_eq!(unit_of("slowing_onset_s"), "s");
        assert_eq!(unit_of("yaw_rate_sign_changes"), "1");
        assert_eq!(unit_of("throughput_vph"), "veh/h");
        assert_eq!(unit_of("unmerged_vehicles"), "1");
        assert_eq!(canonical_unit("m/s²"), Some("m/s^2"));
        assert_eq!(canonical_unit("deg/s"), None);
    }

    #[test]
    fn endpoints_are_checked_against_vehicles_and_figures() {
        let vehicles = vec!["ego".to_string(), "obstacle".to_string()];
        let e = EndpointFigure::parse("obstacle.max_abs_yaw_rate_radps", &vehicles).unwrap();
        assert_eq!(e.vehicle.as_deref(), Some("obstacle"));
        assert!(EndpointFigure::parse("obstacle.merge_zone_rms_yaw_rate_radps", &vehicles).is_ok());
        assert!(EndpointFigure::parse("min_ttc_s", &vehicles).is_ok());
        let throughput = EndpointFigure::parse("throughput_vph", &vehicles).unwrap();
        assert_eq!(
            (throughput.vehicle.as_ref(), throughput.unit()),
            (None, "veh/h")
        );
        assert!(EndpointFigure::parse("unmerged_vehicles", &vehicles).is_ok());
        for bad in [
            "truck.max_abs_yaw_rate_radps",
            "ego.max_yaw",
            "peak",
            "ego.pre_contact",
        ] {
            let err = EndpointFigure::parse(bad, &vehicles).unwrap_err();
            assert!(err.contains("unknown endpoint"), "{bad}: {err}");
        }
    }
}
