//! Straight-line braking against the friction-limited distance v²/(2μg) and, with locked
//! wheels, against the Magic Formula's sliding friction.

mod validation_step;

use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};
use vehicles::{GRAVITY_MPS2, PRESET_NAMES, TireParams, VehicleParams};

fn braking(vehicle_params: VehicleParams, name: &str, speed_mps: f64, mu: f64) -> (f64, f64) {
    let cfg = ManeuverConfig {
        kind: ManeuverKind::Braking,
        vehicle: name.into(),
        vehicle_params: Some(vehicle_params),
        speed_mps,
        steer_rad: 0.0,
        mu,
        duration_s: 20.0,
        step_time_s: 0.5,
        trace_period_s: 0.0,
        dt_s: validation_step::validation_dt_s(),
        ..ManeuverConfig::default()
    };
    let report = run_maneuver(&cfg).unwrap();
    let distance = report.stopping_distance_m.expect("stops");
    let v = report.speed_mps;
    (distance, v * v / (2.0 * mu * GRAVITY_MPS2))
}

/// Full braking (ABS) from 20 m/s at μ = 0.8 stops within 0.95–1.3 × v²/(2μg), every preset.
#[test]
fn full_braking_stops_near_friction_limited_distance() {
    for name in PRESET_NAMES {
        let params = VehicleParams::preset(name).unwrap();
        let (distance, reference) = braking(params, name, 20.0, 0.8);
        let ratio = distance / reference;
        assert!(
            (0.95..=1.3).contains(&ratio),
            "{name}: {distance} m vs {reference} m ({ratio})"
        );
    }
    // Low friction as well.
    let (distance, reference) = braking(VehicleParams::default(), "bmw_320i", 20.0, 0.3);
    let ratio = distance / reference;
    assert!(
        (0.95..=1.3).contains(&ratio),
        "μ 0.3: {distance} vs {reference}"
    );
}

/// Without ABS the brakes lock the wheels (κ = −1); the car then slides on the Magic Formula's
/// locked-wheel friction μ_slide = μ·sin(C atan(B κ_x − E(B κ_x − atan B κ_x))) at κ_x = −1 + S_Hx
/// (pure-slip formula, CommonRoad coefficients), and stops after v²/(2 μ_slide g).
#[test]
fn locked_wheels_slide_on_magic_formula_sliding_friction() {
    let params = VehicleParams {
        abs_enabled: false,
        ..VehicleParams::default()
    };
    let mu = 0.8;
    let t = TireParams::default();
    let b = t.p_kx1 / (t.p_cx1 * mu);
    let x = b * (-1.0 + t.p_hx1);
    let mu_slide = -mu * (t.p_cx1 * (x - t.p_ex1 * (x - x.atan())).atan()).sin();
    assert!(mu_slide > 0.4 && mu_slide < mu, "{mu_slide}");
    let (distance, _) = braking(params, "bmw_320i (no ABS)", 20.0, mu);
    let reference = 20.0 * 20.0 / (2.0 * mu_slide * GRAVITY_MPS2);
    let ratio = distance / reference;
    assert!(
        (0.95..=1.1).contains(&ratio),
        "{distance} m vs {reference} m"
    );
}
