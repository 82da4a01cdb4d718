//! Attractive potential field, paper Eq. 1, on the straight `MergeRoad` (X along it). The
//! planners pull along the target lane's centreline (`PotentialField::moving_target_gradient`);
//! this is the reference of the tests and the `lane_road_field` bench.
//!
//! U_AT = ½ λ (X − X_tar)². The paper leaves X_tar open; read literally, a fixed target makes
//! the pull fade to zero as the vehicle approaches it. We read X_tar as a moving target a
//! look-ahead distance ahead of the point being evaluated along +X (the road direction), so
//! the pull is the constant λ·look-ahead while stepping (Eq. 7), and the fixed-target form
//! below is what is drawn (target = ego X + look-ahead).

/// The numbers of Eq. 1 (λ and the moving target's look-ahead), built once from
/// `PlannerParams` (`derived_params`); the pull λ·look-ahead is the unit of force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttractionParams {
    /// λ, slope scale of U_AT = ½ λ (X − X_tar)² (1/m²; `attractive_gain_per_m2`).
    pub gain_per_m2: f64,
    /// Distance of the moving target X_tar ahead of the point being stepped (m;
    /// `target_lookahead_m`).
    pub lookahead_m: f64,
}

/// The attractive field of Eq. 1 with a target at `target_x_m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttractiveField {
    /// λ (1/m²).
    pub gain_per_m2: f64,
    /// X_tar (m).
    pub target_x_m: f64,
}

impl AttractiveField {
    /// U_AT at longitudinal position `x_m` (Eq. 1).
    pub fn value(&self, x_m: f64) -> f64 {
        let dx = x_m - self.target_x_m;
        0.5 * self.gain_per_m2 * dx * dx
    }

    /// ∇U_AT = [λ (X − X_tar), 0].
    pub fn gradient(&self, x_m: f64) -> [f64; 2] {
        [self.gain_per_m2 * (x_m - self.target_x_m), 0.0]
    }

    /// ∇U_AT with the target re-anchored `lookahead_m` ahead of the evaluated point: the
    /// constant [−λ·look-ahead, 0] used while stepping the local path.
    pub fn moving_target_gradient(gain_per_m2: f64, lookahead_m: f64) -> [f64; 2] {
        [-gain_per_m2 * lookahead_m, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_central_difference() {
        let field = AttractiveField {
            gain_per_m2: 0.07,
            target_x_m: 12.0,
        };
        for x in [-30.0, 0.0, 11.0, 12.0, 40.5] {
            let h = 1e-5;
            let fd = (field.value(x + h) - field.value(x - h)) / (2.0 * h);
            assert!((field.gradient(x)[0] - fd).abs() < 1e-7, "x = {x}");
        }
    }

    #[test]
    fn moving_target_pull_equals_fixed_target_gradient_at_lookahead() {
        let field = AttractiveField {
            gain_per_m2: 0.05,
            target_x_m: 20.0,
        };
        assert_eq!(
            field.gradient(0.0),
            AttractiveField::moving_target_gradient(0.05, 20.0)
        );
    }
}
