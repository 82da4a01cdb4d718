//! Fixed-step explicit integration of a model's state derivative: the classical fourth-order
//! Runge–Kutta scheme, the input held constant over the step (zero-order hold).
//!
//! ```text
//! k₁ = f(x),  k₂ = f(x + h/2·k₁),  k₃ = f(x + h/2·k₂),  k₄ = f(x + h·k₃)
//! x(t + h) = x + h/6 · (k₁ + 2k₂ + 2k₃ + k₄)
//! ```
//! The reference script `scripts/commonroad_models_reference.py` integrates the Python
//! package's derivative functions with the same formula, evaluated in the same order.
//!
//! **Step size.** The scheme is explicit, so a step must resolve the fastest mode of the model
//! (the real-axis stability limit of RK4 is |λ|·h ≲ 2.79). For the ks model any step that
//! resolves the inputs is fine. The st model's sideslip and yaw modes scale as 1/v: with the
//! BMW 320i, λ ≈ −μ·C_S·g / v ≈ −215 s⁻¹·(1 m/s)/v, so h = 0.01 s is stable above about
//! 0.8 m/s and h = 1 ms down to its switch to the kinematic model at 0.1 m/s. The std model's
//! wheel-spin modes are stiffer: near free rolling λ ≈ −R_w²·K_x / (I_w·u_w) with the tyre's
//! slip stiffness K_x = p_kx1·F_z, for the BMW about −7500 s⁻¹ (rear) to −9200 s⁻¹ (front)
//! times (1 m/s)/u_w, so h = 1 ms needs wheel ground speeds above about 3.3 m/s; the reference
//! manoeuvres that crawl to a stop run at h = 0.1 ms. (CommonRoad's own examples use a stiff
//! adaptive solver.)

/// A state that the integrator can handle as `N` numbers in CommonRoad's order.
pub trait CommonRoadState<const N: usize>: Copy {
    /// Its components in CommonRoad's order.
    fn to_array(&self) -> [f64; N];
    /// The state from its components in CommonRoad's order.
    fn from_array(values: [f64; N]) -> Self;
}

/// One RK4 step of length `dt_s` (s) of `derivative` from `x`. The derivative returns, in the
/// state's own type, the rate of each component (unit per second).
pub fn step_rk4<const N: usize, S: CommonRoadState<N>>(
    derivative: impl Fn(&S) -> S,
    x: &S,
    dt_s: f64,
) -> S {
    let xs = x.to_array();
    let stage = |k: &[f64; N], h: f64| S::from_array(std::array::from_fn(|i| xs[i] + h * k[i]));
    let k1 = derivative(x).to_array();
    let k2 = derivative(&stage(&k1, 0.5 * dt_s)).to_array();
    let k3 = derivative(&stage(&k2, 0.5 * dt_s)).to_array();
    let k4 = derivative(&stage(&k3, dt_s)).to_array();
    S::from_array(std::array::from_fn(|i| {
        xs[i] + dt_s / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    }))
}
