//! The scenario's geometric checks, after every value is in range: where the vehicles start on
//! the road and against each other ([`Scenario::validate`]).

use super::*;

impl Scenario {
    /// The geometric checks of a scenario whose values are in range (see `validate`).
    pub(super) fn check_geometry(
        &self,
        origin: &str,
        at: &dyn Fn(Option<Vec<String>>) -> Line,
    ) -> Result<(), ScenarioError> {
        if !self.sim.is_straight_merge_road() {
            return self.check_lane_geometry(origin, at);
        }
        let road = &self.sim.road;
        // Axis-aligned hull of each vehicle's body over the randomisation box (bodies are boxes
        // centred on the centre of gravity, spawned with zero yaw).
        let mut hulls = Vec::with_capacity(self.vehicles.len());
        for v in &self.vehicles {
            let params =
                vehicles::VehicleParams::preset(&v.preset).map_err(|e| ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(self.nominal_path(&format!("vehicles[{}].preset", v.name))),
                    field: Some(format!("vehicles[{}].preset", v.name)),
                    message: e.to_string(),
                })?;
            let b = self.randomise.vehicle_bounds(&v.name);
            let (half_l, half_w) = (0.5 * params.length_m, 0.5 * params.width_m);
            // `validate_vehicles` refused lanes the merge road does not have.
            let lane = v.lane.merge_lane().unwrap_or(Lane::Lower);
            let y_c = road.lane_center_y_m(lane) + v.y_offset_m;
            let x = [v.x_m + b.x_m[0] - half_l, v.x_m + b.x_m[1] + half_l];
            let y = [
                y_c + b.y_offset_m[0] - half_w,
                y_c + b.y_offset_m[1] + half_w,
            ];
            let x_entry = || {
                self.randomise
                    .vehicle_entry_path(&v.name, "x_m")
                    .or_else(|| self.nominal_path(&format!("vehicles[{}].x_m", v.name)))
            };
            if lane == Lane::Lower && x[1] > road.merge_end_x_m {
                return Err(ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(x_entry()),
                    field: Some(format!("vehicles[{}].x_m", v.name)),
                    message: format!(
                        "vehicles[{}].x_m = {} (randomised up to {}): the front of a vehicle in \
                         the lower lane must start before road.merge_end_x_m = {}, where that \
                         lane ends",
                        v.name,
                        v.x_m,
                        v.x_m + b.x_m[1],
                        road.merge_end_x_m
                    ),
                });
            }
            // The body must lie on the road surface at spawn, over the whole randomisation box:
            // inside [start_x_m, end_x_m] and between the edges (the lower edge at its highest
            // point under the body, since it rises through the merge section).
            let lower_edge_m = road.lower_edge_y_m(x[0]).max(road.lower_edge_y_m(x[1]));
            let off_road = if x[0] < road.start_x_m || x[1] > road.end_x_m {
                Some(format!(
                    "its body spans x = [{:.3}, {:.3}] m, beyond the road's [road.start_x_m, \
                     road.end_x_m] = [{}, {}] m",
                    x[0], x[1], road.start_x_m, road.end_x_m
                ))
            } else if y[0] < lower_edge_m || y[1] > road.y_upper_m() {
                Some(format!(
                    "its body spans y = [{:.3}, {:.3}] m, beyond the road's edges [{:.3}, {:.3}] m \
                     there{}",
                    y[0],
                    y[1],
                    lower_edge_m,
                    road.y_upper_m(),
                    if lower_edge_m > road.y_bottom_m + 1e-9 {
                        " (the lower lane narrows in the merge section: start it further back)"
                    } else {
                        ""
                    }
                ))
            } else {
                None
            };
            if let Some(why) = off_road {
                let y_entry = self
                    .randomise
                    .vehicle_entry_path(&v.name, "y_offset_m")
                    .or_else(|| self.nominal_path(&format!("vehicles[{}].y_offset_m", v.name)));
                // Off the side where the lower edge tapers: the position along the road is the
                // cause, not the lateral offset.
                let in_taper = lower_edge_m > road.y_bottom_m + 1e-9;
                let lateral = why.starts_with("its body spans y") && !in_taper;
                let field = format!(
                    "vehicles[{}].{}",
                    v.name,
                    if lateral { "y_offset_m" } else { "x_m" }
                );
                return Err(ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(if lateral { y_entry } else { x_entry() }),
                    message: format!(
                        "{field}: vehicles[{}] must start on the road, including \
                         randomisation: {why}",
                        v.name
                    ),
                    field: Some(field),
                });
            }
            // The road must be long enough for the whole run: every vehicle driving the whole
            // duration at the highest speed it starts at, aims at or is prescribed, plus
            // ROAD_END_SPEED_ALLOWANCE for overshoot, stays on it.
            let top_speed_mps = top_speed_mps(v, &b);
            let reach_m = x[1] + top_speed_mps * self.sim.duration_s;
            if reach_m > road.end_x_m {
                return Err(ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(self.nominal_path("road.end_x_m")),
                    field: Some("road.end_x_m".into()),
                    message: format!(
                        "road.end_x_m = {}: too short for vehicles[{}], which can reach x = {:.1} \
                         m in duration_s = {} s (front at {:.1} m, {:.2} m/s = its highest \
                         initial, target or prescribed speed including randomisation, + {:.0} \
                         %); lengthen the road or shorten the run",
                        road.end_x_m,
                        v.name,
                        reach_m,
                        self.sim.duration_s,
                        x[1],
                        top_speed_mps,
                        100.0 * ROAD_END_SPEED_ALLOWANCE
                    ),
                });
            }
            for (other, ox, oy) in &hulls {
                let overlap = |a: [f64; 2], o: &[f64; 2]| a[0] < o[1] && o[0] < a[1];
                if overlap(x, ox) && overlap(y, oy) {
                    return Err(ScenarioError::Invalid {
                        origin: origin.to_string(),
                        line: at(x_entry()),
                        field: Some(format!("vehicles[{}].x_m", v.name)),
                        message: format!(
                            "vehicles[{}].x_m = {}: its body can overlap that of vehicle {other} \
                             at spawn (x over [{:.3}, {:.3}] m vs [{:.3}, {:.3}] m, including \
                             randomisation)",
                            v.name, v.x_m, x[0], x[1], ox[0], ox[1]
                        ),
                    });
                }
            }
            hulls.push((v.name.clone(), x, y));
        }
        Ok(())
    }
}
