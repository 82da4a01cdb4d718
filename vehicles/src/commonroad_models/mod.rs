//! CommonRoad's vehicle models ks, st and std in pure Rust (no physics engine): the state
//! derivative ẋ = f(x, u, p) of each, the input constraints they apply, CommonRoad's parameter
//! sets, and a fixed-step RK4 integrator.
//!
//! Written from the equations of Althoff, M. and Würsching, G., *CommonRoad: Vehicle Models*
//! (2020), and checked against the Python package `commonroad-vehicle-models` 3.0.2: the same
//! inputs integrated alike agree to 1e-6 relative on every state component
//! (`vehicles/tests/commonroad_models.rs`, fixture made by
//! `scripts/commonroad_models_reference.py`; docs/vehicle_models.md). Where the package's
//! formulas differ from the textbook ones, the package's are kept and the difference is said in
//! the module that has it ([`st`]'s kinematic β̇, [`tire`]'s longitudinal vertical shift).
//!
//! | model | module | state (CommonRoad's order) | reference point |
//! |---|---|---|---|
//! | ks: kinematic single track | [`ks`] | [`KsState`]: s_x, s_y, δ, v, ψ | rear axle |
//! | st: single track, linear tyres | [`st`] | [`StState`]: s_x, s_y, δ, v, ψ, ψ̇, β | centre of mass |
//! | std: single-track drift, Magic-Formula tyres, wheel spin | [`drift`] | [`StdState`]: the st states, ω_f, ω_r | centre of mass |
//!
//! Every model takes the same input [`CommonRoadInput`]: u₁ the steering velocity (rad/s), u₂
//! the longitudinal acceleration (m/s²), limited by [`constrain_steering_velocity`] and
//! [`constrain_acceleration`] inside the derivative. Parameters: [`CommonRoadVehicleParams`]
//! (its [`Default`] is CommonRoad vehicle 2, the BMW 320i; also vehicles 1 and 3). Integration:
//! [`ks_step_rk4`], [`st_step_rk4`], [`std_step_rk4`], or the generic [`step_rk4`] over any
//! [`CommonRoadState`]; step sizes in [`integrate`].
//!
//! # Public API
//! - Parameters: [`CommonRoadVehicleParams`] ([`CommonRoadSteeringLimits`],
//!   [`CommonRoadLongitudinalLimits`], [`CommonRoadTireParams`]), checked by
//!   [`CommonRoadVehicleParams::validate`] ([`CommonRoadParamsError`]).
//! - Input and its constraints: [`CommonRoadInput`], [`constrain_input`],
//!   [`constrain_steering_velocity`], [`constrain_acceleration`].
//! - Models: [`ks_derivative`] (and [`ks_cog_derivative`]), [`st_derivative`],
//!   [`std_derivative`] ([`std_dynamic_weight`]); the Magic-Formula tyre in [`tire`].
//! - Integration: [`step_rk4`] with [`CommonRoadState`]; [`ks_step_rk4`], [`st_step_rk4`],
//!   [`std_step_rk4`].

pub mod constraints;
pub mod drift;
pub mod integrate;
pub mod ks;
pub mod params;
pub mod st;
pub mod tire;
pub mod validation;

pub use constraints::{
    CommonRoadInput, constrain_acceleration, constrain_input, constrain_steering_velocity,
};
pub use drift::{StdState, std_derivative, std_dynamic_weight, std_step_rk4};
pub use integrate::{CommonRoadState, step_rk4};
pub use ks::{KsState, ks_cog_derivative, ks_derivative, ks_step_rk4};
pub use params::{
    CommonRoadLongitudinalLimits, CommonRoadSteeringLimits, CommonRoadTireParams,
    CommonRoadVehicleParams,
};
pub use st::{StState, st_derivative, st_step_rk4};
pub use validation::CommonRoadParamsError;
