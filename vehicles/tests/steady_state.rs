//! Steady-state cornering against the linear single-track model (closed forms in
//! `vehicles::single_track`) and against the quasi-static roll equation.

mod validation_step;

use vehicles::maneuver::{ManeuverConfig, ManeuverKind, ManeuverReport, run_maneuver};
use vehicles::{GRAVITY_MPS2, LinearSingleTrack, PRESET_NAMES, VehicleParams};

fn steady_state(vehicle: &str, speed_mps: f64, steer_rad: f64) -> ManeuverReport {
    let cfg = ManeuverConfig {
        kind: ManeuverKind::SteadyState,
        vehicle: vehicle.into(),
        speed_mps,
        steer_rad,
        mu: 0.9,
        trace_period_s: 0.0,
        dt_s: validation_step::validation_dt_s(),
        ..ManeuverConfig::default()
    };
    run_maneuver(&cfg).unwrap()
}

/// Yaw rate within 10 % of r = v δ / (L + K_us v²) below 2 m/s², at 10–25 m/s, every preset.
#[test]
fn yaw_rate_matches_single_track_model_below_2_mps2() {
    for vehicle in PRESET_NAMES {
        let params = VehicleParams::preset(vehicle).unwrap();
        let model = LinearSingleTrack::from_params(&params);
        for speed in [10.0, 15.0, 20.0, 25.0] {
            // Steer for ~1.5 m/s² according to the model: δ = a (L + K v²) / v².
            let l_eff =
                model.wheelbase_m() + model.understeer_gradient_rad_per_mps2() * speed * speed;
            let steer = 1.5 * l_eff / (speed * speed);
            let report = steady_state(vehicle, speed, steer);
            assert!(
                report.lat_accel_mps2.abs() < 2.0,
                "{vehicle} {speed}: {report:?}"
            );
            // Reference at the speed and steer actually held.
            let reference = model.steady_state_yaw_rate_radps(report.speed_mps, report.steer_rad);
            let error = (report.yaw_rate_radps - reference).abs() / reference.abs();
            assert!(
                error < 0.10,
                "{vehicle} at {speed} m/s: r = {} vs {reference} ({:.2} %)",
                report.yaw_rate_radps,
                100.0 * error
            );
            // Steady state means a_y = v r.
            let vr = report.speed_mps * report.yaw_rate_radps;
            assert!(
                (report.lat_accel_mps2 - vr).abs() < 0.02 * vr.abs(),
                "{report:?}"
            );
            assert!(
                (report.speed_mps - speed).abs() < 0.05,
                "speed held: {}",
                report.speed_mps
            );
        }
    }
}

/// Sideslip at the CoG for a small left turn: positive and close to the kinematic l_r δ / L at
/// low speed, negative at high speed, changing sign near v_β0 = √(l_r C_r L / (m l_f)), and
/// matching β = δ (l_r − m v² l_f / (C_r L)) / (L + K_us v²) in magnitude.
#[test]
fn sideslip_sign_and_magnitude_follow_single_track_model() {
    for vehicle in PRESET_NAMES {
        let params = VehicleParams::preset(vehicle).unwrap();
        let model = LinearSingleTrack::from_params(&params);
        let l = model.wheelbase_m();

        let low = steady_state(vehicle, 5.0, 0.02);
        let kinematic = model.lr_m * low.steer_rad / l;
        assert!(low.sideslip_rad > 0.0, "{vehicle}: {low:?}");
        assert!(
            (low.sideslip_rad - kinematic).abs() < 0.15 * kinematic,
            "{vehicle}: β = {} vs kinematic {kinematic}",
            low.sideslip_rad
        );
        let reference = model.steady_state_sideslip_rad(low.speed_mps, low.steer_rad);
        assert!(
            (low.sideslip_rad - reference).abs() < 0.05 * reference.abs(),
            "{vehicle}: β = {} vs {reference}",
            low.sideslip_rad
        );

        let high = steady_state(vehicle, 25.0, 0.006);
        let reference = model.steady_state_sideslip_rad(high.speed_mps, high.steer_rad);
        assert!(high.sideslip_rad < 0.0, "{vehicle}: {high:?}");
        assert!(
            (high.sideslip_rad - reference).abs() < 0.10 * reference.abs(),
            "{vehicle}: β = {} vs {reference}",
            high.sideslip_rad
        );

        let v0 = model.sideslip_sign_change_speed_mps();
        let below = steady_state(vehicle, v0 - 3.0, 0.01);
        let above = steady_state(vehicle, v0 + 3.0, 0.01);
        assert!(
            below.sideslip_rad > 0.0,
            "{vehicle} below {v0}: {}",
            below.sideslip_rad
        );
        assert!(
            above.sideslip_rad < 0.0,
            "{vehicle} above {v0}: {}",
            above.sideslip_rad
        );
    }
}

/// Settled roll against the quasi-static roll equation of a body rolling about a ground-level
/// axis on corner springs k_i at half-tracks t_i/2 (no anti-roll bars):
/// φ = m a_y h / (K_φ − m g h), K_φ = Σ k_i (t_i / 2)².
#[test]
fn roll_angle_matches_quasi_static_roll_equation() {
    for vehicle in PRESET_NAMES {
        let p = VehicleParams::preset(vehicle).unwrap();
        let report = steady_state(vehicle, 20.0, 0.01);
        let k_phi = 2.0 * p.spring_rate_front_npm * (0.5 * p.track_front_m).powi(2)
            + 2.0 * p.spring_rate_rear_npm * (0.5 * p.track_rear_m).powi(2);
        let mgh = p.mass_kg * GRAVITY_MPS2 * p.cog_height_m;
        // A left turn (a_y > 0) rolls the body right side down (φ > 0).
        let expected = p.mass_kg * report.lat_accel_mps2 * p.cog_height_m / (k_phi - mgh);
        assert!(
            (report.roll_rad - expected).abs() < 0.10 * expected,
            "{vehicle}: roll {} vs {expected}",
            report.roll_rad
        );
    }
}

/// Far beyond the linear range (steer for 2× the friction limit) the car settles at a lateral
/// acceleration just below μ·g: the friction circle caps it, and ABS/traction control keep it
/// from spinning.
#[test]
fn lateral_acceleration_saturates_at_friction_limit() {
    for mu in [0.5, 0.8] {
        let cfg = ManeuverConfig {
            kind: ManeuverKind::SteadyState,
            speed_mps: 20.0,
            steer_rad: 2.0 * mu * GRAVITY_MPS2 * 2.58 / 400.0,
            mu,
            trace_period_s: 0.0,
            dt_s: validation_step::validation_dt_s(),
            ..ManeuverConfig::default()
        };
        let report = run_maneuver(&cfg).unwrap();
        let limit = mu * GRAVITY_MPS2;
        assert!(report.lat_accel_mps2 <= 1.01 * limit, "μ {mu}: {report:?}");
        assert!(report.lat_accel_mps2 >= 0.85 * limit, "μ {mu}: {report:?}");
        assert!((report.speed_mps - 20.0).abs() < 0.5, "μ {mu}: {report:?}");
    }
}
