//! Colours and names of the recording: the vehicles' palette, the field's viridis scale and its
//! normalisation, entity-path parts, the yaw as a quaternion.

#[cfg(feature = "rerun")]
use rerun::datatypes::Quaternion;

use super::FieldColorScale;
use mergesim_types::VehicleId;

/// Colours of vehicles by id: the paper's green ego and blue obstacle first, then the
/// Tableau-10 palette.
const VEHICLE_PALETTE: [[u8; 3]; 8] = [
    [44, 160, 44],
    [31, 119, 180],
    [255, 127, 14],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [188, 189, 34],
];

/// Viridis sampled at nine evenly spaced points (matplotlib), interpolated linearly.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The palette colour of vehicle `id`.
pub fn vehicle_color(id: VehicleId) -> [u8; 3] {
    VEHICLE_PALETTE[(id as usize) % VEHICLE_PALETTE.len()]
}

/// Viridis colour of `t` in [0, 1] (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let scaled = t * (VIRIDIS.len() - 1) as f64;
    let i = (scaled.floor() as usize).min(VIRIDIS.len() - 2);
    let f = scaled - i as f64;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let a = f64::from(VIRIDIS[i][c]);
        let b = f64::from(VIRIDIS[i + 1][c]);
        *o = (a + f * (b - a)).round() as u8;
    }
    out
}

/// Maps `values` to [0, 1] with `scale`; non-finite values map to `None`.
pub fn normalize_field(values: &[f64], scale: FieldColorScale) -> Vec<Option<f64>> {
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let min = finite.clone().fold(f64::INFINITY, f64::min);
    let max = finite.fold(f64::NEG_INFINITY, f64::max);
    let range = max - min;
    values
        .iter()
        .map(|&v| {
            if !v.is_finite() {
                return None;
            }
            if !range.is_finite() || range <= 0.0 {
                return Some(0.0);
            }
            Some(match scale {
                FieldColorScale::Linear => (v - min) / range,
                FieldColorScale::Log => (v - min).ln_1p() / range.ln_1p(),
            })
        })
        .collect()
}

/// Turns a free-form name into one entity-path part: ASCII letters, digits, `_` and `-` kept,
/// everything else replaced by `_`.
pub fn entity_part(name: &str) -> String {
    let part: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if part.is_empty() { "_".into() } else { part }
}

#[cfg(feature = "rerun")]
pub(crate) fn yaw_quaternion(yaw_rad: f64) -> Quaternion {
    let half = 0.5 * yaw_rad;
    Quaternion::from_xyzw([0.0, 0.0, half.sin() as f32, half.cos() as f32])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_hits_its_control_points_and_clamps() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        assert_eq!(viridis(-3.0), VIRIDIS[0]);
        assert_eq!(viridis(f64::NAN), VIRIDIS[0]);
        // Half way between two control points is their mean.
        let mid = viridis(1.0 / 16.0);
        for c in 0..3 {
            let expected = 0.5 * (f64::from(VIRIDIS[0][c]) + f64::from(VIRIDIS[1][c]));
            assert!((f64::from(mid[c]) - expected).abs() <= 0.5);
        }
    }

    #[test]
    fn normalize_field_maps_min_and_max() {
        let v = [2.0, 4.0, f64::NAN, 10.0];
        let lin = normalize_field(&v, FieldColorScale::Linear);
        assert_eq!(lin, vec![Some(0.0), Some(0.25), None, Some(1.0)]);
        let log = normalize_field(&v, FieldColorScale::Log);
        let expected = 3.0_f64.ln() / 9.0_f64.ln();
        assert!((log[1].unwrap() - expected).abs() < 1e-12);
        assert_eq!(log[3], Some(1.0));
        assert_eq!(
            normalize_field(&[5.0, 5.0], FieldColorScale::Log),
            vec![Some(0.0); 2]
        );
    }

    #[test]
    fn entity_parts_are_sanitised() {
        assert_eq!(entity_part("ego car/1"), "ego_car_1");
        assert_eq!(entity_part("yaw_rate_radps"), "yaw_rate_radps");
        assert_eq!(entity_part(""), "_");
    }

    #[test]
    fn yaw_quaternion_rotates_x_onto_heading() {
        let yaw = 0.7_f64;
        let [x, y, z, w] = yaw_quaternion(yaw).xyzw().map(f64::from);
        // Rotate (1, 0, 0) by q: first column of the rotation matrix.
        let rx = 1.0 - 2.0 * (y * y + z * z);
        let ry = 2.0 * (x * y + w * z);
        assert!((rx - yaw.cos()).abs() < 1e-6 && (ry - yaw.sin()).abs() < 1e-6);
    }
}
