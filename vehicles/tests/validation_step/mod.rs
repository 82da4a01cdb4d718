//! The physics step of the validation tests (steady_state.rs, braking.rs): the maneuvers'
//! default (`ManeuverConfig::default().dt_s`, 2 ms, the simulator's default), or the value of
//! the environment variable `MERGESIM_VALIDATION_DT_S` (seconds), which runs the same
//! assertions at another step (`benches/physics_step_validity.sh`). An unreadable value fails
//! the test that reads it, naming the variable; a step outside the physics world's range
//! fails in `run_maneuver` with its own error.

use vehicles::maneuver::ManeuverConfig;

/// The environment variable that sets the validation tests' physics step (s).
pub const DT_ENV: &str = "MERGESIM_VALIDATION_DT_S";

/// The physics step (s) of every maneuver of the validation tests.
pub fn validation_dt_s() -> f64 {
    match std::env::var(DT_ENV) {
        Err(std::env::VarError::NotPresent) => ManeuverConfig::default().dt_s,
        Err(e) => panic!("{DT_ENV}: {e}"),
        Ok(text) => match text.trim().parse::<f64>() {
            Ok(dt_s) => dt_s,
            Err(e) => panic!("{DT_ENV} = {text:?}: not a number of seconds ({e})"),
        },
    }
}
