//! CommonRoad's ks, st and std models (`vehicles::commonroad_models`) against the Python
//! package `commonroad-vehicle-models` 3.0.2: the fixture tests/data/commonroad_models/
//! reference.json is written by scripts/commonroad_models_reference.py, which integrates the
//! package's own derivative functions with the same fixed-step RK4 as `step_rk4`, input held per
//! step. Here every manoeuvre is replayed from its initial state with its input segments, and
//! every recorded state component must agree.
//!
//! Tolerance: |rust − python| ≤ 1e-6·|python| + 1e-9. The relative part is the check (the same
//! equations evaluated in a different order of floating-point operations: the differences seen
//! are printed with `--nocapture`). The absolute floor of 1e-9 (in each component's SI unit:
//! 1 nm, 1 nrad, 1 nm/s, …) is for components that are 0 in exact arithmetic and only rounding
//! noise in both programs — the lateral position and yaw of a straight run, the speed after
//! braking to a stop — where a relative comparison of two noises means nothing; it is six orders
//! below every such component's scale in these manoeuvres (metres, tenths of radians).
//!
//! The fixture also holds the package's parameter values of vehicles 1–3; the constructors of
//! `CommonRoadVehicleParams` must equal them exactly.

use serde_json::Value;
use vehicles::commonroad_models::{
    CommonRoadInput, CommonRoadState, CommonRoadVehicleParams, KsState, StState, StdState,
    ks_step_rk4, st_step_rk4, std_step_rk4,
};

const REL: f64 = 1e-6;
const ABS_FLOOR: f64 = 1e-9;

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/commonroad_models/reference.json"
    );
    let text = std::fs::read_to_string(path).expect("the fixture is committed");
    serde_json::from_str(&text).expect("the fixture is JSON")
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(num).collect()
}

fn params(id: u64) -> CommonRoadVehicleParams {
    CommonRoadVehicleParams::commonroad_vehicle(id as u32).expect("vehicles 1-3")
}

/// The package's parameter values, field by field, equal the Rust constructors.
#[test]
fn parameter_sets_equal_the_package() {
    let r = reference();
    let vehicles = r["vehicles"].as_object().expect("vehicles");
    assert_eq!(vehicles.len(), 3);
    for (id, v) in vehicles {
        let p = params(id.parse().expect("an id"));
        let scalars = [
            ("l", p.length_m),
            ("w", p.width_m),
            ("m", p.mass_kg),
            ("I_z", p.yaw_inertia_kgm2),
            ("a", p.cog_to_front_axle_m),
            ("b", p.cog_to_rear_axle_m),
            ("h_cg", p.cog_height_m),
            ("h_s", p.sprung_cog_height_m),
            ("I_y_w", p.wheel_inertia_kgm2),
            ("R_w", p.wheel_radius_m),
            ("T_sb", p.brake_torque_front_share),
            ("T_se", p.drive_torque_front_share),
        ];
        for (name, value) in scalars {
            assert_eq!(value, num(&v[name]), "vehicle {id} {name}");
        }
        let s = &v["steering"];
        assert_eq!(p.steering.min_angle_rad, num(&s["min"]), "vehicle {id}");
        assert_eq!(p.steering.max_angle_rad, num(&s["max"]), "vehicle {id}");
        assert_eq!(p.steering.min_steering_velocity_radps, num(&s["v_min"]));
        assert_eq!(p.steering.max_steering_velocity_radps, num(&s["v_max"]));
        let l = &v["longitudinal"];
        assert_eq!(p.longitudinal.min_speed_mps, num(&l["v_min"]), "vehicle {id}");
        assert_eq!(p.longitudinal.max_speed_mps, num(&l["v_max"]), "vehicle {id}");
        assert_eq!(p.longitudinal.switching_speed_mps, num(&l["v_switch"]));
        assert_eq!(p.longitudinal.max_acceleration_mps2, num(&l["a_max"]));
        // The tyre table through serde: CommonRoad's names are the field names.
        let tire: serde_json::Map<String, Value> = serde_json::to_value(p.tire)
            .expect("serialisable")
            .as_object()
            .expect("a struct")
            .clone();
        let reference_tire = v["tire"].as_object().expect("tire");
        assert_eq!(tire.len(), reference_tire.len(), "vehicle {id}");
        for (name, value) in reference_tire {
            assert_eq!(num(&tire[name]), num(value), "vehicle {id} tire.{name}");
        }
    }
}

/// Largest error of one manoeuvre: (relative error over the components above the floor's
/// reach, absolute error of the others).
#[derive(Default, Clone, Copy)]
struct Errors {
    rel: f64,
    abs_near_zero: f64,
}

fn replay<const N: usize, S: CommonRoadState<N>>(
    m: &Value,
    step: impl Fn(&S, &CommonRoadInput, f64) -> S,
    names: &[&str; N],
) -> Errors {
    let name = m["name"].as_str().expect("a name");
    let dt_s = num(&m["dt_s"]);
    let every = m["record_every"].as_u64().expect("K") as usize;
    let recorded: Vec<Vec<f64>> = m["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(nums)
        .collect();
    let initial = nums(&m["initial_state"]);
    let mut x = S::from_array(initial.try_into().expect("state length"));
    let mut states = vec![x.to_array()];
    let mut n = 0usize;
    for seg in m["segments"].as_array().expect("segments") {
        let u = CommonRoadInput {
            steering_velocity_radps: num(&seg["steering_velocity_radps"]),
            acceleration_mps2: num(&seg["acceleration_mps2"]),
        };
        for _ in 0..seg["steps"].as_u64().expect("steps") {
            x = step(&x, &u, dt_s);
            n += 1;
            if n % every == 0 {
                states.push(x.to_array());
            }
        }
    }
    if n % every != 0 {
        states.push(x.to_array());
    }
    assert_eq!(states.len(), recorded.len(), "{name}: number of records");
    let mut e = Errors::default();
    for (k, (ours, theirs)) in states.iter().zip(&recorded).enumerate() {
        for i in 0..N {
            let (a, b) = (ours[i], theirs[i]);
            let diff = (a - b).abs();
            assert!(
                diff <= REL * b.abs() + ABS_FLOOR,
                "{name}: record {k} (step {}), {}: rust {a:e}, python {b:e}, \
                 relative error {:e}",
                k * every,
                names[i],
                diff / b.abs()
            );
            if b.abs() * REL > ABS_FLOOR {
                e.rel = e.rel.max(diff / b.abs());
            } else {
                e.abs_near_zero = e.abs_near_zero.max(diff);
            }
        }
    }
    e
}

#[test]
fn trajectories_equal_the_package() {
    let r = reference();
    assert_eq!(
        r["package"].as_str(),
        Some("commonroad-vehicle-models 3.0.2")
    );
    let mut worst: std::collections::BTreeMap<String, Errors> = Default::default();
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    for m in r["manoeuvres"].as_array().expect("manoeuvres") {
        let p = params(m["vehicle"].as_u64().expect("a vehicle id"));
        let model = m["model"].as_str().expect("a model");
        let e = match model {
            "ks" => replay::<5, KsState>(
                m,
                |x, u, dt| ks_step_rk4(x, u, &p, dt),
                &["s_x", "s_y", "delta", "v", "psi"],
            ),
            "st" => replay::<7, StState>(
                m,
                |x, u, dt| st_step_rk4(x, u, &p, dt),
                &["s_x", "s_y", "delta", "v", "psi", "psi_dot", "beta"],
            ),
            "std" => replay::<9, StdState>(
                m,
                |x, u, dt| std_step_rk4(x, u, &p, dt),
                &[
                    "s_x", "s_y", "delta", "v", "psi", "psi_dot", "beta", "omega_f", "omega_r",
                ],
            ),
            other => panic!("unknown model {other}"),
        };
        println!(
            "{:<34} max relative error {:.2e}, max absolute error where |value| < 1e-3: {:.2e}",
            m["name"].as_str().unwrap_or("?"),
            e.rel,
            e.abs_near_zero
        );
        let w = worst.entry(model.to_string()).or_default();
        w.rel = w.rel.max(e.rel);
        w.abs_near_zero = w.abs_near_zero.max(e.abs_near_zero);
        *counts.entry(model.to_string()).or_default() += 1;
    }
    for (model, e) in &worst {
        println!(
            "{model}: {} manoeuvres, max relative error {:.2e}, max absolute error near zero {:.2e}",
            counts[model], e.rel, e.abs_near_zero
        );
    }
    assert_eq!(counts.len(), 3, "every model is checked");
}
