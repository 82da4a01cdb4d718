//! The friction speed limit of Eq. 10a.

/// the segment's ends and middle. κ → 0 is guarded: below μ g / V_limit² the limit is V_limit.
pub(crate) fn friction_speed_limits(
    curvature_per_m: impl Fn(f64) -> f64,
    waypoint_xi_m: &[f64],
    mu: f64,
    speed_limit_mps: f64,
) -> Vec<f64> {
    let mu_g = mu.max(0.0) * crate::params::GRAVITY_MPS2;
    let mut previous = 0.0;
    waypoint_xi_m
        .iter()
        .map(|&xi| {
            let kappa = [previous, 0.5 * (previous + xi), xi]
                .iter()
                .map(|&x| curvature_per_m(x).abs())
                .fold(0.0, f64::max);
            previous = xi;
            if kappa * speed_limit_mps * speed_limit_mps <= mu_g {
                speed_limit_mps
            } else {
                (mu_g / kappa).sqrt()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn friction_limit_is_sqrt_mu_g_over_kappa() {
        let kappa = 0.02;
        let limits = friction_speed_limits(|_| kappa, &[5.0, 10.0], 0.8, 30.0);
        let expected = (0.8 * crate::params::GRAVITY_MPS2 / kappa).sqrt();
        assert!((limits[0] - expected).abs() < 1e-12);
        let straight = friction_speed_limits(|_| 0.0, &[5.0], 0.8, 30.0);
        assert_eq!(straight, vec![30.0]);
    }
}
