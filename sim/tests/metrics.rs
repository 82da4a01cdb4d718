//! Metrics against closed forms: sign changes of a sinusoidal yaw rate, circle-arc path length,
//! ∫|r|, RMS and jerk of a sinusoidal acceleration.

use std::f64::consts::PI;

use sim::TimeSeriesRow;
use sim::metrics::{MetricsError, MetricsParams, VehicleMetrics};

fn sample(t_s: f64) -> TimeSeriesRow {
    TimeSeriesRow {
        t_s,
        vehicle: "ego".into(),
        x_m: 0.0,
        y_m: 0.0,
        yaw_rad: 0.0,
        yaw_rate_radps: 0.0,
        sideslip_rad: 0.0,
        speed_mps: 10.0,
        planned_speed_mps: 10.0,
        accel_long_mps2: 0.0,
        accel_lat_mps2: 0.0,
    }
}

#[test]
fn sinusoidal_yaw_rate_counts_two_changes_per_period_minus_one() {
    // r = A sin(ωt) over 3 full periods: the sign alternates + - + - + -, i.e. 5 changes.
    let amplitude = 0.3;
    let omega = 2.0 * PI / 4.0;
    let dt = 0.01;
    let mut m = VehicleMetrics::new("ego");
    let n = (3.0 * 4.0 / dt) as usize;
    for k in 0..=n {
        let t = k as f64 * dt;
        m.push(&TimeSeriesRow {
            yaw_rate_radps: amplitude * (omega * t).sin(),
            ..sample(t)
        })
        .unwrap();
    }
    let s = m.summary();
    assert_eq!(s.yaw_rate_sign_changes, 5);
    assert!((s.max_abs_yaw_rate_radps - amplitude).abs() < 1e-6);
    // ∫|A sin ωt| over 3 periods = 3 · 4A/ω. The piecewise-linear integral errs by at most
    // T·dt²·max|r''|/12 = T·dt²·Aω²/12.
    let exact = 3.0 * 4.0 * amplitude / omega;
    let bound = 12.0 * dt * dt * amplitude * omega * omega / 12.0;
    assert!(
        (s.integral_abs_yaw_rate_rad - exact).abs() <= bound,
        "{} vs {exact} (bound {bound})",
        s.integral_abs_yaw_rate_rad
    );
}

#[test]
fn noise_below_the_threshold_and_dither_do_not_count() {
    // Small oscillation below the 0.02 rad/s threshold: no change.
    let mut m = VehicleMetrics::new("ego");
    for k in 0..1000 {
        let t = k as f64 * 0.01;
        m.push(&TimeSeriesRow {
            yaw_rate_radps: 0.015 * (20.0 * t).sin(),
            ..sample(t)
        })
        .unwrap();
    }
    assert_eq!(m.summary().yaw_rate_sign_changes, 0);

    // Hysteresis: +, small -, +, - beyond the threshold = one change only.
    let mut m = VehicleMetrics::new("ego");
    for (k, r) in [0.03, -0.01, 0.03, 0.0, -0.03, -0.05].iter().enumerate() {
        m.push(&TimeSeriesRow {
            yaw_rate_radps: *r,
            ..sample(k as f64)
        })
        .unwrap();
    }
    assert_eq!(m.summary().yaw_rate_sign_changes, 1);
}

#[test]
fn path_length_of_a_circle_arc_is_its_chord_sum_and_close_to_r_phi() {
    let radius = 50.0;
    let arc = 2.0; // rad
    let n = 240usize;
    let dtheta = arc / n as f64;
    let mut m = VehicleMetrics::new("ego");
    for k in 0..=n {
        let theta = k as f64 * dtheta;
        m.push(&TimeSeriesRow {
            x_m: radius * theta.cos(),
            y_m: radius * theta.sin(),
            yaw_rad: theta + PI / 2.0,
            ..sample(k as f64 * 0.05)
        })
        .unwrap();
    }
    let s = m.summary();
    // Sum of n equal chords: n · 2R sin(Δθ/2) (exact), and R·φ·(1 − Δθ²/24) to O(Δθ⁴).
    let chords = n as f64 * 2.0 * radius * (0.5 * dtheta).sin();
    assert!((s.path_length_m - chords).abs() < 1e-9);
    assert!((s.path_length_m - radius * arc).abs() < radius * arc * dtheta * dtheta / 20.0);
    // Heading wraps: from π/2 to π/2 + 2 > π, |yaw| peaks within one step of π.
    assert!(s.max_abs_yaw_rad <= PI && s.max_abs_yaw_rad > PI - dtheta);
}

#[test]
fn acceleration_rms_jerk_and_extremes_match_closed_forms() {
    // a_long = A sin(ωt) over 2 periods: RMS A/√2; jerk Aω cos(ωt): peak Aω, RMS Aω/√2.
    let amp = 2.0;
    let omega = 2.0 * PI;
    let dt = 0.001;
    let mut m = VehicleMetrics::new("ego");
    let n = (2.0 / dt) as usize;
    for k in 0..=n {
        let t = k as f64 * dt;
        let speed = 10.0 + 3.0 * (t - 1.3).powi(2);
        m.push(&TimeSeriesRow {
            accel_long_mps2: amp * (omega * t).sin(),
            accel_lat_mps2: -1.0,
            sideslip_rad: 0.05 * (omega * t).cos(),
            speed_mps: speed,
            ..sample(t)
        })
        .unwrap();
    }
    let s = m.summary();
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(s.rms_accel_long_mps2, amp / 2f64.sqrt()) < 1e-5);
    assert!(rel(s.peak_abs_accel_long_mps2, amp) < 1e-5);
    // Finite differences of a sine are Aω·cos(ω·t_mid)·sinc(ωdt/2): the sinc costs (ωdt)²/24
    // and the sampled peak sits half a step from cos = 1, costing (ωdt/2)²/2.
    assert!(rel(s.peak_abs_jerk_long_mps3, amp * omega) < (omega * dt).powi(2) / 6.0);
    assert!(s.peak_abs_jerk_long_mps3 <= amp * omega);
    assert!(rel(s.rms_jerk_long_mps3, amp * omega / 2f64.sqrt()) < 1e-5);
    // Constant lateral acceleration: RMS = |a|, no jerk.
    assert!((s.rms_accel_lat_mps2 - 1.0).abs() < 1e-12);
    assert_eq!(s.peak_abs_jerk_lat_mps3, 0.0);
    // Speed minimum of the parabola at t = 1.3 s.
    assert!((s.min_speed_mps - 10.0).abs() < 1e-9);
    assert!((s.t_min_speed_s - 1.3).abs() < 1e-9);
    assert!((s.max_abs_sideslip_rad - 0.05).abs() < 1e-12);
    assert!((s.duration_s - 2.0).abs() < 1e-9);
}

#[test]
fn oscillation_window_counts_only_inside_it() {
    let params = MetricsParams {
        oscillation_window_x_m: Some([100.0, 200.0]),
        ..MetricsParams::default()
    };
    let mut m = VehicleMetrics::with_params("ego", params).unwrap();
    // Driving along x at 20 m/s for 15 s (x from 0 to 300 m), r = 0.1 sin(2πt/2).
    let dt = 0.01;
    for k in 0..=1500 {
        let t = k as f64 * dt;
        m.push(&TimeSeriesRow {
            x_m: 20.0 * t,
            yaw_rate_radps: 0.1 * (PI * t).sin(),
            ..sample(t)
        })
        .unwrap();
    }
    let s = m.summary();
    // Whole run: 7.5 periods -> 14 changes. Inside x ∈ [100, 200] (t ∈ [5, 10]): sign at
    // t = 5+ is negative (sin(5π+) < 0), changes at t = 6, 7, 8, 9 -> 4.
    assert_eq!(s.yaw_rate_sign_changes, 14);
    assert_eq!(s.window_yaw_rate_sign_changes, Some(4));
    // ∫|0.1 sin πt| over 5 s = 5 half-periods · 0.2/π.
    // Piecewise-linear integration error bound: T·dt²·A·ω²/12.
    let expected = 5.0 * 0.2 / PI;
    let bound = 5.0 * dt * dt * 0.1 * PI * PI / 12.0;
    let w = s.window_integral_abs_yaw_rate_rad.unwrap();
    assert!((w - expected).abs() <= bound, "{w} vs {expected}");
}

#[test]
fn collided_flag_json_names_and_errors() {
    let mut m = VehicleMetrics::new("obstacle");
    assert_eq!(m.summary().samples, 0);
    m.push(&sample(0.0)).unwrap();
    m.set_collided();
    let json = serde_json::to_value(m.summary()).unwrap();
    for field in [
        "id",
        "max_abs_sideslip_rad",
        "max_abs_yaw_rad",
        "max_abs_yaw_rate_radps",
        "min_speed_mps",
        "t_min_speed_s",
        "path_length_m",
        "yaw_rate_sign_changes",
        "collided",
    ] {
        assert!(json.get(field).is_some(), "missing {field}");
    }
    assert_eq!(json["id"], "obstacle");
    assert_eq!(json["collided"], true);

    assert!(matches!(
        m.push(&sample(0.0)),
        Err(MetricsError::TimeNotIncreasing { .. })
    ));
    assert!(matches!(
        m.push(&TimeSeriesRow {
            speed_mps: f64::NAN,
            ..sample(1.0)
        }),
        Err(MetricsError::NonFinite {
            field: "speed_mps",
            ..
        })
    ));
    let bad = MetricsParams {
        oscillation_window_x_m: Some([5.0, 1.0]),
        ..MetricsParams::default()
    };
    assert!(VehicleMetrics::with_params("x", bad).is_err());
}
