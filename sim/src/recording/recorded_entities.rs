//! Recorded traffic in the recording: `world/recorded_vehicles`, one grey box (its recorded
//! length × width, axis-aligned like the simulated vehicles') labelled with its name per
//! recorded vehicle present at the logged instant. An instant without any logs an empty set,
//! so a vehicle whose span has ended disappears.

use rerun::Boxes2D;
use rerun::components::Color;

use crate::body_state::BodyState;

use super::{Recorder, RecordingError};

/// Grey: recorded vehicles stand apart from the simulated ones' palette.
pub const RECORDED_VEHICLE_RGB: [u8; 3] = [150, 150, 150];
/// Drawn with the simulated vehicles (`entities`' `DRAW_VEHICLES`), just below them.
const DRAW_RECORDED_VEHICLES: f32 = 19.0;

impl Recorder {
    /// Logs the recorded vehicles present now as grey boxes; `names[i]` labels `bodies[i]`.
    pub fn log_recorded_vehicles(
        &mut self,
        bodies: &[BodyState],
        names: &[String],
    ) -> Result<(), RecordingError> {
        let radius_m = self.params.vehicle_outline_radius_m as f32;
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        if names.len() != bodies.len() {
            return Err(RecordingError::InvalidInput {
                call: "log_recorded_vehicles",
                reason: format!("{} bodies but {} names", bodies.len(), names.len()),
            });
        }
        for body in bodies {
            if let Some((field, value)) = body.first_invalid_field() {
                return Err(RecordingError::InvalidInput {
                    call: "log_recorded_vehicles",
                    reason: format!("vehicle {}: {field} = {value}", body.id),
                });
            }
        }
        let [r, g, b] = RECORDED_VEHICLE_RGB;
        active.stream.log(
            "world/recorded_vehicles",
            &Boxes2D::from_centers_and_half_sizes(
                bodies.iter().map(|b| [b.x_m as f32, b.y_m as f32]),
                bodies
                    .iter()
                    .map(|b| [(0.5 * b.length_m) as f32, (0.5 * b.width_m) as f32]),
            )
            .with_colors([Color::from_rgb(r, g, b)])
            .with_labels(names.iter().map(String::as_str))
            .with_radii([radius_m])
            .with_draw_order(DRAW_RECORDED_VEHICLES),
        )?;
        Ok(())
    }
}
