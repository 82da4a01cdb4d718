//! Constrained cubic fit of the waypoints, paper Eqs. 8–9.
//!
//! In the vehicle frame at planning time (origin at the vehicle, ξ along its heading, η to its
//! left) the path is η = f(x̂) = a0 + a1 x̂ + a2 x̂² + a3 x̂³ with x̂ = ξ / S, S the ξ of the last
//! waypoint, so x̂ ∈ [0, 1] and the Vandermonde matrix stays well conditioned.
//!
//! The QP of Eq. 9, written out (decision vector a = [a0, a1, a2, a3]):
//!
//! ```text
//!   minimise   ½ (X a − Y)ᵀ W (X a − Y)  =  ½ aᵀ (XᵀWX) a − (XᵀWY)ᵀ a + const
//!   subject to a_min ≤ a ≤ a_max
//! ```
//!
//! with rows [1, x̂_k, x̂_k², x̂_k³] of X, one per data point: the vehicle's own position
//! (0, 0) with weight `cubic_origin_weight`, then the N waypoints with weight 1. The bounds
//! follow Lin et al. 2022 (the paper's reference for a_min, a_max), in metric terms:
//!
//! ```text
//!   |a0| ≤ offset_max                 lateral offset of the path at the vehicle
//!   |a1| ≤ S tan(ψ_max)               heading  f'(0)/S  relative to the vehicle
//!   |a2| ≤ S² κ_max / 2               curvature f''(0)/S² = 2 a2 / S²
//!   |a3| ≤ S³ κ'_max / 6              curvature rate f'''/S³ = 6 a3 / S³
//! ```
//!
//! so that |κ(ξ)| ≤ κ_max + κ'_max ξ along the path (small-slope approximation).
//! Clarabel solves the QP; when the unconstrained weighted least-squares solution (a 4×4
//! Cholesky solve) already satisfies the bounds it *is* the QP optimum and Clarabel is skipped.

use clarabel::algebra::CscMatrix;
use clarabel::solver::NonnegativeConeT;
use nalgebra::{Matrix4, Vector4};

use crate::clarabel_setup::{ProgramSettings, new_solver, solve_checked};
use crate::error::PlannerError;

/// The limits behind Eq. 9a's coefficient bounds (module doc), built once from
/// `PlannerParams` (`derived_params`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicLimits {
    /// offset_max, bound on |a0|, the lateral offset of the path at the vehicle (m).
    pub max_offset_m: f64,
    /// ψ_max, bound on the path heading at the vehicle, relative to it (rad): |a1| ≤ S tan ψ_max.
    pub max_heading_rad: f64,
    /// κ_max, bound on the curvature at the vehicle (1/m): |a2| ≤ S² κ_max / 2.
    pub max_curvature_per_m: f64,
    /// κ'_max, bound on the curvature rate (1/m²): |a3| ≤ S³ κ'_max / 6.
    pub max_curvature_rate_per_m2: f64,
}

/// Everything the fit of Eqs. 8–9 reads (module doc), built once from `PlannerParams`
/// (`derived_params`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicFitParams {
    /// Weight of the vehicle's own position (0, 0) as a data point (waypoints weigh 1): the
    /// diagonal of W in Eq. 9 (`cubic_origin_weight`).
    pub origin_weight: f64,
    /// The limits of Eq. 9a.
    pub limits: CubicLimits,
    /// Clarabel's `max_iter` for the QP of Eq. 9 (`solver_max_iterations`).
    pub solver_max_iterations: u32,
    /// Clarabel's tolerances for the QP of Eq. 9 (`solver_tolerance`).
    pub solver_tolerance: f64,
}

/// Box bounds on the coefficients (Eq. 9a).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CoefficientBounds {
    /// a_min.
    pub lower: [f64; 4],
    /// a_max.
    pub upper: [f64; 4],
}

impl CoefficientBounds {
    /// Symmetric bounds from the heading / curvature / curvature-rate limits for a path whose
    /// x is scaled by `x_scale_m` (module doc).
    pub fn from_limits(limits: &CubicLimits, x_scale_m: f64) -> Self {
        let s = x_scale_m;
        let upper = [
            limits.max_offset_m,
            s * limits.max_heading_rad.tan(),
            s * s * limits.max_curvature_per_m / 2.0,
            s * s * s * limits.max_curvature_rate_per_m2 / 6.0,
        ];
        Self {
            lower: upper.map(|u| -u),
            upper,
        }
    }

    fn contains(&self, a: &[f64; 4]) -> bool {
        (0..4).all(|k| a[k] >= self.lower[k] && a[k] <= self.upper[k])
    }
}

/// How the fit was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitMethod {
    /// The unconstrained least-squares solution satisfied every bound.
    Unconstrained,
    /// A bound was active: Clarabel solved the QP.
    Qp,
}

/// Normal equations M = XᵀWX, r = XᵀWY of the weighted fit.
fn normal_equations(x: &[f64], y: &[f64], w: &[f64]) -> (Matrix4<f64>, Vector4<f64>) {
    let mut m = Matrix4::zeros();
    let mut r = Vector4::zeros();
    for ((&xk, &yk), &wk) in x.iter().zip(y).zip(w) {
        let row = Vector4::new(1.0, xk, xk * xk, xk * xk * xk);
        m += wk * row * row.transpose();
        r += wk * yk * row;
    }
    (m, r)
}

/// Solves the box-constrained QP ½ aᵀMa − rᵀa, lower ≤ a ≤ upper with Clarabel.
///
/// Decision vector a = [a0..a3]; P = M (upper triangle), q = −r;
/// rows 0..4: a ≤ upper (A = I, b = upper); rows 4..8: −a ≤ −lower (A = −I, b = −lower),
/// all in the nonnegative cone.
pub(crate) fn solve_box_qp(
    m: &Matrix4<f64>,
    r: &Vector4<f64>,
    bounds: &CoefficientBounds,
    max_iterations: u32,
    tolerance: f64,
) -> Result<[f64; 4], PlannerError> {
    let finite = m.iter().chain(r.iter()).all(|v| v.is_finite())
        && bounds
            .lower
            .iter()
            .chain(&bounds.upper)
            .all(|v| v.is_finite());
    if !finite {
        return Err(PlannerError::NonFinite {
            what: "cubic_fit QP data".into(),
        });
    }
    // Upper triangle of M, column by column.
    let mut colptr = vec![0usize];
    let mut rowval = Vec::with_capacity(10);
    let mut nzval = Vec::with_capacity(10);
    for col in 0..4 {
        for row in 0..=col {
            rowval.push(row);
            nzval.push(m[(row, col)]);
        }
        colptr.push(rowval.len());
    }
    let p = CscMatrix::new(4, 4, colptr, rowval, nzval);
    let q: Vec<f64> = r.iter().map(|v| -v).collect();
    // A = [I; −I] (8 × 4): column k has +1 in row k and −1 in row 4 + k.
    let a = CscMatrix::new(
        8,
        4,
        vec![0, 2, 4, 6, 8],
        vec![0, 4, 1, 5, 2, 6, 3, 7],
        vec![1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0],
    );
    let mut b = bounds.upper.to_vec();
    b.extend(bounds.lower.iter().map(|v| -v));
    let cones = [NonnegativeConeT(8)];
    let settings = ProgramSettings {
        max_iterations,
        tolerance,
        scaling_and_refinement: true,
    };
    let mut solver = new_solver("cubic_fit", &p, &q, &a, &b, &cones, &settings)?;
    let x = solve_checked(&mut solver, "cubic_fit", 4)?;
    // Interior-point iterates sit a hair inside or outside the box: snap to it.
    Ok([0, 1, 2, 3].map(|k| x[k].clamp(bounds.lower[k], bounds.upper[k])))
}

/// Weighted least-squares cubic through (x_k, y_k) with weights w_k, within `bounds` (Eq. 9).
pub(crate) fn fit_bounded_cubic(
    x: &[f64],
    y: &[f64],
    w: &[f64],
    bounds: &CoefficientBounds,
    max_iterations: u32,
    tolerance: f64,
) -> Result<([f64; 4], FitMethod), PlannerError> {
    if x.len() != y.len() || x.len() != w.len() || x.len() < 4 {
        return Err(PlannerError::invalid(
            "cubic_fit.points",
            x.len() as f64,
            "need at least 4 points with as many y and weights",
        ));
    }
    let (m, r) = normal_equations(x, y, w);
    if let Some(cholesky) = m.cholesky() {
        let a = cholesky.solve(&r);
        let a = [a[0], a[1], a[2], a[3]];
        if a.iter().all(|v| v.is_finite()) && bounds.contains(&a) {
            return Ok((a, FitMethod::Unconstrained));
        }
    }
    solve_box_qp(&m, &r, bounds, max_iterations, tolerance).map(|a| (a, FitMethod::Qp))
}

/// The fitted path: a cubic in the vehicle frame at planning time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicPath {
    /// Vehicle position at planning time (m).
    pub origin_xy_m: [f64; 2],
    /// cos of the vehicle's yaw at planning time.
    pub cos_yaw: f64,
    /// sin of the vehicle's yaw at planning time.
    pub sin_yaw: f64,
    /// a0..a3 with x scaled by `x_scale_m`.
    pub coefficients: [f64; 4],
    /// S (m).
    pub x_scale_m: f64,
    /// How the coefficients were obtained.
    pub method: FitMethod,
}

impl CubicPath {
    /// World point → vehicle frame (ξ, η).
    pub fn to_local(&self, p: [f64; 2]) -> [f64; 2] {
        let dx = p[0] - self.origin_xy_m[0];
        let dy = p[1] - self.origin_xy_m[1];
        [
            self.cos_yaw * dx + self.sin_yaw * dy,
            -self.sin_yaw * dx + self.cos_yaw * dy,
        ]
    }

    /// η = f(ξ / S) (m).
    pub(crate) fn lateral_m(&self, xi_m: f64) -> f64 {
        let [a0, a1, a2, a3] = self.coefficients;
        let u = xi_m / self.x_scale_m;
        a0 + u * (a1 + u * (a2 + u * a3))
    }

    /// dη/dξ.
    pub(crate) fn slope(&self, xi_m: f64) -> f64 {
        let [_, a1, a2, a3] = self.coefficients;
        let u = xi_m / self.x_scale_m;
        (a1 + u * (2.0 * a2 + 3.0 * u * a3)) / self.x_scale_m
    }

    /// d²η/dξ² (1/m).
    pub(crate) fn second_derivative_per_m(&self, xi_m: f64) -> f64 {
        let [_, _, a2, a3] = self.coefficients;
        let u = xi_m / self.x_scale_m;
        (2.0 * a2 + 6.0 * a3 * u) / (self.x_scale_m * self.x_scale_m)
    }

    /// Signed curvature κ = η'' / (1 + η'²)^{3/2} of the cubic at ξ (1/m). The paper's
    /// κ = 6 a3 s + 2 a2 ≈ 2 a2 is the small-slope, unscaled form of the same quantity.
    pub(crate) fn curvature_per_m(&self, xi_m: f64) -> f64 {
        let d1 = self.slope(xi_m);
        let d2 = self.second_derivative_per_m(xi_m);
        d2 / (1.0 + d1 * d1).powf(1.5)
    }

    /// World point of the cubic at ξ.
    pub(crate) fn world_point(&self, xi_m: f64) -> [f64; 2] {
        let eta = self.lateral_m(xi_m);
        [
            self.origin_xy_m[0] + self.cos_yaw * xi_m - self.sin_yaw * eta,
            self.origin_xy_m[1] + self.sin_yaw * xi_m + self.cos_yaw * eta,
        ]
    }
}

/// Fits the path cubic (Eqs. 8–9) to world waypoints for a vehicle at `origin_xy_m` with yaw
/// `yaw_rad`. Returns the path and the ξ of each waypoint. Fails (typed, no panic) when the
/// waypoints do not advance along the vehicle's heading (a cubic η(ξ) cannot hold them) or the
/// QP fails.
pub fn fit_path_cubic(
    params: &CubicFitParams,
    origin_xy_m: [f64; 2],
    yaw_rad: f64,
    waypoints: &[[f64; 2]],
) -> Result<(CubicPath, Vec<f64>), PlannerError> {
    let (sin_yaw, cos_yaw) = yaw_rad.sin_cos();
    let mut path = CubicPath {
        origin_xy_m,
        cos_yaw,
        sin_yaw,
        coefficients: [0.0; 4],
        x_scale_m: 1.0,
        method: FitMethod::Unconstrained,
    };
    let local: Vec<[f64; 2]> = waypoints.iter().map(|p| path.to_local(*p)).collect();
    if local.iter().flatten().any(|v| !v.is_finite()) {
        return Err(PlannerError::NonFinite {
            what: "waypoints".into(),
        });
    }
    let mut previous_xi = 0.0;
    for p in &local {
        // (finite: checked above)
        if p[0] <= previous_xi + 1e-6 {
            return Err(PlannerError::SolverFailed {
                problem: "cubic_fit".into(),
                status: "waypoints do not advance along the vehicle heading".into(),
            });
        }
        previous_xi = p[0];
    }
    let x_scale_m = previous_xi;
    let mut xs = Vec::with_capacity(local.len() + 1);
    let mut ys = Vec::with_capacity(local.len() + 1);
    let mut ws = Vec::with_capacity(local.len() + 1);
    xs.push(0.0);
    ys.push(0.0);
    ws.push(params.origin_weight);
    for p in &local {
        xs.push(p[0] / x_scale_m);
        ys.push(p[1]);
        ws.push(1.0);
    }
    let bounds = CoefficientBounds::from_limits(&params.limits, x_scale_m);
    let (coefficients, method) = fit_bounded_cubic(
        &xs,
        &ys,
        &ws,
        &bounds,
        params.solver_max_iterations,
        params.solver_tolerance,
    )?;
    path.coefficients = coefficients;
    path.x_scale_m = x_scale_m;
    path.method = method;
    let xis = local.iter().map(|p| p[0]).collect();
    Ok((path, xis))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn loose() -> CoefficientBounds {
        CoefficientBounds {
            lower: [-1e3; 4],
            upper: [1e3; 4],
        }
    }

    fn sample(a: [f64; 4], n: usize) -> (Vec<f64>, Vec<f64>) {
        let xs: Vec<f64> = (0..n).map(|k| k as f64 / (n - 1) as f64).collect();
        let ys = xs
            .iter()
            .map(|x| a[0] + a[1] * x + a[2] * x * x + a[3] * x * x * x)
            .collect();
        (xs, ys)
    }

    #[test]
    fn recovers_a_known_cubic_exactly_both_ways() {
        let truth = [0.2, -1.5, 3.0, -0.7];
        let (xs, ys) = sample(truth, 21);
        let ws: Vec<f64> = (0..21).map(|k| 1.0 + k as f64 * 0.1).collect();
        let (a, method) = fit_bounded_cubic(&xs, &ys, &ws, &loose(), 50, 1e-9).unwrap();
        assert_eq!(method, FitMethod::Unconstrained);
        for k in 0..4 {
            assert!((a[k] - truth[k]).abs() < 1e-10, "{a:?}");
        }
        // Through Clarabel as well (bounds inactive).
        let (m, r) = normal_equations(&xs, &ys, &ws);
        let a = solve_box_qp(&m, &r, &loose(), 50, 1e-9).unwrap();
        for k in 0..4 {
            assert!((a[k] - truth[k]).abs() < 1e-6, "{a:?}");
        }
    }

    /// Reference for an active bound: with a2 fixed at its bound, the optimum of the remaining
    /// three coefficients is an ordinary weighted least-squares problem (KKT with one active
    /// constraint), solved here by its own 3×3 normal equations.
    #[test]
    fn active_curvature_bound_matches_the_reduced_least_squares() {
        let truth = [0.0, 0.5, 4.0, -1.0];
        let (xs, ys) = sample(truth, 15);
        let ws = vec![1.0; 15];
        let bounds = CoefficientBounds {
            lower: [-10.0, -10.0, -1.0, -10.0],
            upper: [10.0, 10.0, 1.0, 10.0],
        };
        let (a, method) = fit_bounded_cubic(&xs, &ys, &ws, &bounds, 100, 1e-10).unwrap();
        assert_eq!(method, FitMethod::Qp);
        assert!((a[2] - 1.0).abs() < 1e-6, "a2 = {}", a[2]);
        // Reduced problem: y − 1.0·x² ≈ b0 + b1 x + b3 x³.
        let mut m = nalgebra::Matrix3::<f64>::zeros();
        let mut r = nalgebra::Vector3::<f64>::zeros();
        for (&x, &y) in xs.iter().zip(&ys) {
            let row = nalgebra::Vector3::new(1.0, x, x * x * x);
            m += row * row.transpose();
            r += (y - x * x) * row;
        }
        let b = m.cholesky().unwrap().solve(&r);
        assert!((a[0] - b[0]).abs() < 1e-5, "{a:?} vs {b:?}");
        assert!((a[1] - b[1]).abs() < 1e-5, "{a:?} vs {b:?}");
        assert!((a[3] - b[2]).abs() < 1e-5, "{a:?} vs {b:?}");
        // Every coefficient inside its box.
        assert!(bounds.contains(&a));
    }

    #[test]
    fn path_fit_reproduces_a_cubic_path_in_a_rotated_vehicle_frame() {
        let params = CubicFitParams::from(&crate::params::PlannerParams::default());
        let yaw: f64 = 0.2;
        let origin = [10.0, 3.0];
        // A gentle cubic in the vehicle frame, well inside the default bounds.
        let s = 80.0;
        let truth = [0.0, 0.8, 1.5, -0.9];
        let waypoints: Vec<[f64; 2]> = (1..=20)
            .map(|k| {
                let xi = s * k as f64 / 20.0;
                let u = xi / s;
                let eta = truth[0] + truth[1] * u + truth[2] * u * u + truth[3] * u * u * u;
                [
                    origin[0] + yaw.cos() * xi - yaw.sin() * eta,
                    origin[1] + yaw.sin() * xi + yaw.cos() * eta,
                ]
            })
            .collect();
        let (path, xis) = fit_path_cubic(&params, origin, yaw, &waypoints).unwrap();
        assert_eq!(xis.len(), 20);
        assert!((path.x_scale_m - s).abs() < 1e-9);
        for (a, t) in path.coefficients.iter().zip(truth) {
            assert!((a - t).abs() < 1e-8, "{:?}", path.coefficients);
        }
        for (p, xi) in waypoints.iter().zip(&xis) {
            let q = path.world_point(*xi);
            assert!((p[0] - q[0]).abs() < 1e-8 && (p[1] - q[1]).abs() < 1e-8);
        }
        // Curvature against a central difference of the heading of the world points.
        let xi = 37.0;
        let h = 1e-3;
        let heading = |xi: f64| {
            let a = path.world_point(xi - 1e-4);
            let b = path.world_point(xi + 1e-4);
            (b[1] - a[1]).atan2(b[0] - a[0])
        };
        let arc = |xi: f64| {
            let a = path.world_point(xi);
            let b = path.world_point(xi + h);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
        };
        let numeric = (heading(xi + h) - heading(xi)) / arc(xi);
        assert!((path.curvature_per_m(xi + 0.5 * h) - numeric).abs() < 1e-5);
    }

    #[test]
    fn waypoints_behind_the_vehicle_are_a_typed_error() {
        let params = CubicFitParams::from(&crate::params::PlannerParams::default());
        let waypoints: Vec<[f64; 2]> = (1..=6).map(|k| [-(k as f64), 0.0]).collect();
        let err = fit_path_cubic(&params, [0.0, 0.0], 0.0, &waypoints).unwrap_err();
        assert!(matches!(err, PlannerError::SolverFailed { .. }));
    }
}
