//! Colours and names of the recording: the vehicles' palette, the field's viridis scale and its
//! normalisation on a fixed range and its colour-bar ticks, entity-path parts, the 2D views' frame.

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

/// The one colour of vehicle `id` (its position in the scenario's vehicle list), used by every
/// output that draws vehicles: the Rerun recording, the PNG figures (`merge_sim compare
/// --plots`) and the GIF (`merge_sim run --gif`), so a vehicle has the same RGB in all three.
///
/// Ids 0 to 7 take the eight colours of `VEHICLE_PALETTE` (the paper's green ego and blue obstacle first); later
/// ids take hues spaced by the golden angle, at three lightness levels, so no two ids below
/// [`DISTINCT_VEHICLE_COLORS`] share a colour and none is a grey (the road's colours).
pub fn vehicle_color(id: VehicleId) -> [u8; 3] {
    let index = id as usize;
    if let Some(color) = VEHICLE_PALETTE.get(index) {
        return *color;
    }
    let k = (index - VEHICLE_PALETTE.len()) as f64;
    // Golden-ratio steps around the hue circle; the lightness cycles every 7 ids.
    let hue = (0.13 + k * 0.618_033_988_749_895).fract();
    let lightness = [0.50, 0.36, 0.64][((index - VEHICLE_PALETTE.len()) / 7) % 3];
    hsl_to_rgb(hue, 0.75, lightness)
}

/// Ids up to this many get pairwise distinct colours from [`vehicle_color`] (the largest
/// scenario has 200 vehicles).
pub const DISTINCT_VEHICLE_COLORS: u32 = 200;

/// An HSL colour (each in [0, 1]) as RGB.
fn hsl_to_rgb(hue: f64, saturation: f64, lightness: f64) -> [u8; 3] {
    let c = (1.0 - (2.0 * lightness - 1.0).abs()) * saturation;
    let h6 = hue * 6.0;
    let x = c * (1.0 - (h6 % 2.0 - 1.0).abs());
    let (r, g, b) = match h6 as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = lightness - 0.5 * c;
    [r, g, b].map(|v| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8)
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

/// Maps `values` to [0, 1] with `scale` on the fixed range `[lo, hi]` (values outside are
/// clamped); non-finite values map to `None`. A degenerate range (hi ≤ lo, or not finite) maps
/// every finite value to 0.
pub fn normalize_field(
    values: &[f64],
    scale: FieldColorScale,
    range: [f64; 2],
) -> Vec<Option<f64>> {
    values
        .iter()
        .map(|&v| v.is_finite().then(|| scale_position(v, scale, range)))
        .collect()
}

/// Where `v` lies on the colour scale, in [0, 1].
fn scale_position(v: f64, scale: FieldColorScale, [lo, hi]: [f64; 2]) -> f64 {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return 0.0;
    }
    let d = (v - lo).clamp(0.0, span);
    match scale {
        FieldColorScale::Linear => d / span,
        FieldColorScale::Log => d.ln_1p() / span.ln_1p(),
    }
}

/// Labelled ticks of the colour bar: (position in [0, 1], value). Linear: five evenly spaced
/// values; log: lo and lo + 10^k for each power of ten up to the span, and hi.
pub fn field_scale_ticks(scale: FieldColorScale, range: [f64; 2]) -> Vec<(f64, f64)> {
    let [lo, hi] = range;
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return vec![(0.0, lo)];
    }
    let values: Vec<f64> = match scale {
        FieldColorScale::Linear => (0..5).map(|k| lo + span * f64::from(k) / 4.0).collect(),
        FieldColorScale::Log => {
            let mut v = vec![lo];
            let mut step = 1.0;
            while step < span * 0.999 {
                v.push(lo + step);
                step *= 10.0;
            }
            v.push(hi);
            v
        }
    };
    values
        .into_iter()
        .map(|v| (scale_position(v, scale, range), v))
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

/// 180° about X: the frame of the 2D views, in which road Y points up on screen (Rerun's 2D
/// views draw Y down).
#[cfg(feature = "rerun")]
pub(crate) fn y_up_quaternion() -> Quaternion {
    Quaternion::from_xyzw([1.0, 0.0, 0.0, 0.0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vehicle_colours_are_distinct_and_not_grey() {
        assert_eq!(vehicle_color(0), [44, 160, 44]);
        assert_eq!(vehicle_color(1), [31, 119, 180]);
        let colors: Vec<[u8; 3]> = (0..DISTINCT_VEHICLE_COLORS).map(vehicle_color).collect();
        for (i, a) in colors.iter().enumerate() {
            let spread = a.iter().max().unwrap() - a.iter().min().unwrap();
            assert!(spread >= 40, "vehicle {i}: {a:?} is nearly grey");
            for (j, b) in colors.iter().enumerate().take(i) {
                assert_ne!(a, b, "vehicles {i} and {j}");
            }
        }
        // The same id gives the same colour, whoever asks.
        assert_eq!(vehicle_color(37), vehicle_color(37));
    }

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
        let v = [2.0, 4.0, f64::NAN, 10.0, 50.0, -1.0];
        let lin = normalize_field(&v, FieldColorScale::Linear, [2.0, 10.0]);
        assert_eq!(
            lin,
            vec![Some(0.0), Some(0.25), None, Some(1.0), Some(1.0), Some(0.0)]
        );
        let log = normalize_field(&v, FieldColorScale::Log, [2.0, 10.0]);
        let expected = 3.0_f64.ln() / 9.0_f64.ln();
        assert!((log[1].unwrap() - expected).abs() < 1e-12);
        assert_eq!(log[3], Some(1.0));
        assert_eq!(
            normalize_field(&[5.0, 5.0], FieldColorScale::Log, [3.0, 3.0]),
            vec![Some(0.0); 2]
        );
    }

    #[test]
    fn the_scale_is_fixed_not_per_snapshot() {
        // The same value gets the same colour whatever else is in the snapshot.
        let a = normalize_field(&[10.0, 20.0], FieldColorScale::Log, [0.0, 1000.0]);
        let b = normalize_field(&[10.0, 900.0], FieldColorScale::Log, [0.0, 1000.0]);
        assert_eq!(a[0], b[0]);
        assert!(a[0].is_some_and(|t| t > 0.0 && t < 1.0));
    }

    #[test]
    fn ticks_span_the_bar() {
        let t = field_scale_ticks(FieldColorScale::Log, [0.0, 200.0]);
        let values: Vec<f64> = t.iter().map(|p| p.1).collect();
        assert_eq!(values, vec![0.0, 1.0, 10.0, 100.0, 200.0]);
        assert_eq!(t[0].0, 0.0);
        assert_eq!(t[4].0, 1.0);
        assert!(t.windows(2).all(|w| w[0].0 < w[1].0));
        let lin = field_scale_ticks(FieldColorScale::Linear, [0.0, 8.0]);
        assert_eq!(
            lin.iter().map(|p| p.0).collect::<Vec<_>>(),
            vec![0.0, 0.25, 0.5, 0.75, 1.0]
        );
    }

    #[test]
    fn entity_parts_are_sanitised() {
        assert_eq!(entity_part("ego car/1"), "ego_car_1");
        assert_eq!(entity_part("yaw_rate_radps"), "yaw_rate_radps");
        assert_eq!(entity_part(""), "_");
    }
}
