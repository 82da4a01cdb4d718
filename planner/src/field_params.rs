//! The numbers and readings that shape a family of obstacle fields (Eq. 4): the path field's
//! and the interaction term's each have their own (`PlannerParams::path_field`,
//! `PlannerParams::interaction_field`), and who keeps the gap ([`Role`]).

use serde::{Deserialize, Serialize};

use mergesim_types::VehicleShape;

/// Largest |ψ_o| used in the correlation form (rad): C1 = 1 − ψ² and the correlation ψ must stay
/// below 1 for the quadratic form to be positive definite.
pub const MAX_CORRELATION_HEADING_RAD: f64 = 0.9;

/// How Eq. 4 aligns the ellipse with the obstacle's heading (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeadingForm {
    /// Eq. 4's C1/C2 terms as printed: a Gaussian with correlation ψ_o (the `paper` set).
    PaperCorrelation,
    /// The Gaussian evaluated in the obstacle's frame, rotated by ψ_o (the `mergesim` set).
    Rotation,
}

/// How Eq. 4's lateral term decays (module doc of `obstacle_field`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LateralForm {
    /// σ_y = d_lat / √(−2 ln(ε/A)) under the square: a Gaussian that is ε at the lateral
    /// safety distance d_lat (both parameter sets).
    FixedDistance,
    /// σ_y as printed, √(−(Y − Y_o)² / (2 ln(ε/A))) = |Y − Y_o| / k with k = √(−2 ln(ε/A)),
    /// entering Eq. 4 unsquared: the lateral term (Y − Y_o)²/σ_y = k·|Y − Y_o| (a Laplace
    /// profile whose length scale is a unit slip, 1 m) and, in the correlation form,
    /// C2 = 2ψ_o k (X − X_o) sgn(Y − Y_o) / σ_x. An option for attributing the `paper` set's
    /// results; neither set uses it by default.
    PrintedLaplace,
}

/// Which length enters D_min's constant term (l_fr + l_fr,o)/2 (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MinDistanceLength {
    /// The wheelbases l_fr, as printed (the `paper` set): at D_min the bodies overlap.
    Wheelbase,
    /// The body lengths (the `mergesim` set): D_min is at least the contact distance.
    BodyLength,
}

impl MinDistanceLength {
    /// (l + l_o)/2 for the chosen length (m).
    pub(crate) fn half_sum_m(self, me: &VehicleShape, other: &VehicleShape) -> f64 {
        match self {
            MinDistanceLength::Wheelbase => 0.5 * (me.wheelbase_m + other.wheelbase_m),
            MinDistanceLength::BodyLength => 0.5 * (me.length_m + other.length_m),
        }
    }
}

/// The numbers that shape one family of obstacle fields (Eq. 4). The path field (Eq. 7, and
/// PF-SP's risk) and the interaction term (Eq. 10) each have their own, so tuning one never
/// moves the other (`PlannerParams::path_field`, `PlannerParams::interaction_field`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObstacleFieldParams {
    /// A_obs, the peak.
    pub amplitude: f64,
    /// ε, the level at the lateral safety distance.
    pub epsilon: f64,
    /// Lateral safety distance d_lat (m): σ_y = d_lat/√(−2 ln(ε/A)).
    pub lateral_safety_m: f64,
    /// Fraction f of A_obs left at D_min: σ_x = D_min/√(−2 ln f).
    pub fraction_at_min_distance: f64,
    /// Time gap τ added to D_min for the follower, v_f·τ (s).
    pub time_gap_s: f64,
    /// M of the planning vehicle (dimensionless factor).
    pub ego_mass_factor: f64,
    /// M_o of the other vehicle (dimensionless factor).
    pub other_mass_factor: f64,
    /// Heading terms of Eq. 4.
    pub heading_form: HeadingForm,
    /// Length term of D_min.
    pub min_distance_length: MinDistanceLength,
    /// Roles by side (true) or the planning vehicle always the follower (false, as printed).
    pub min_distance_by_side: bool,
    /// The lateral term's form.
    pub lateral_form: LateralForm,
}

impl ObstacleFieldParams {
    /// √(−2 ln f): σ_x = D_min / this.
    pub(crate) fn x_scale(&self) -> f64 {
        (-2.0 * self.fraction_at_min_distance.ln()).sqrt()
    }

    /// k = √(−2 ln(ε/A)) (1/m: the printed σ_y is |Y − Y_o|/k, [`LateralForm::PrintedLaplace`]).
    pub(crate) fn lateral_laplace_rate_per_m(&self) -> f64 {
        (-2.0 * (self.epsilon / self.amplitude).ln()).sqrt()
    }

    /// σ_y (m).
    pub(crate) fn sigma_lateral_m(&self) -> f64 {
        self.lateral_safety_m / self.lateral_laplace_rate_per_m()
    }
}

/// Who keeps the gap between the planning vehicle and another one (module doc of `others`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The full by-side field.
    Full,
    /// The front shrunk to the contact distance (the other follows me where I am ahead of it).
    RearOnly,
    /// Both halves at the contact distance (I lead; the other keeps the gap).
    ContactOnly,
}
