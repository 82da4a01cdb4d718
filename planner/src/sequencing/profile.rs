//! The energy-optimal speed profile into the assigned crossing time, and the constrained
//! profile the car actually follows.
//!
//! ## Unconstrained problem (Rios-Torres & Malikopoulos 2017, the vehicle's problem in the
//! control zone)
//!
//! Double integrator ṗ = v, v̇ = u. Over [t₀, t_f]:
//!
//! ```text
//!   minimise   ½ ∫_{t₀}^{t_f} u(t)² dt
//!   subject to p(t₀) = p₀,  v(t₀) = v₀,  p(t_f) = p_f   (t_f given: the assigned slot)
//! ```
//!
//! The Hamiltonian H = ½u² + λ_p v + λ_v u gives u = −λ_v, λ̇_p = 0, λ̇_v = −λ_p, so u is
//! affine in t: u(t) = a t + b, v(t) = ½ a t² + b t + c, p(t) = a t³/6 + b t²/2 + c t + d.
//! The final speed is free (the merging zone asks for no particular speed, only for the
//! arrival time), so the transversality condition is λ_v(t_f) = 0, i.e. **u(t_f) = 0**. The
//! four conditions are the linear system
//!
//! ```text
//!   ⎡ t₀³/6  t₀²/2  t₀  1 ⎤ ⎡a⎤   ⎡p₀⎤
//!   ⎢ t₀²/2  t₀     1   0 ⎥ ⎢b⎥ = ⎢v₀⎥
//!   ⎢ t_f³/6 t_f²/2 t_f 1 ⎥ ⎢c⎥   ⎢p_f⎥
//!   ⎣ t_f    1      0   0 ⎦ ⎣d⎦   ⎣0 ⎦
//! ```
//!
//! solved here in closed form in the local time τ = t − t₀ (T = t_f − t₀, D = p_f − p₀):
//! u(τ) = α τ + β with β = −α T (from u(T) = 0) and D = v₀ T + α T³/6 + β T²/2 = v₀ T − α T³/3,
//! so **α = 3 (v₀ T − D) / T³, β = −α T**; then a = α, b = β − α t₀,
//! c = v₀ − α t₀²/2 − β t₀ … (the absolute-time constants, [`EnergyOptimalProfile::absolute`]).
//! The arrival speed is v(T) = 1.5 D/T − 0.5 v₀.
//!
//! ## What the unconstrained solution does not guarantee, and the constrained profile
//!
//! Nothing above bounds the speed (v(T) < 0 when the slot is far: T > 3D/v₀), the
//! acceleration, or the gap to the car ahead. The car follows instead the profile integrated
//! forward with step h ([`SequencingParams::profile_step_s`](super::SequencingParams)):
//!
//! ```text
//!   v_des    = min( max(v_opt(τ + h), v_min), v_max, v_safe )
//!   v(τ + h) = min( max(v_des, v(τ) − b_max h), v(τ) + u_max h )           |u| bounds
//!   p(τ + h) = p(τ) + h v(τ + h)
//! ```
//!
//! v_safe is the highest v = v(τ + h) meeting, with the gap g after the step, both forms of the
//! rear-end constraint:
//!
//! ```text
//!   g ≥ δ_safe + ρ v                                  the paper's time-gap form
//!   g ≥ δ_safe + ρ v + v² / 2b_max − v_l² / 2b_max     its braking-distance form (Gipps 1981)
//! ```
//!
//! The first alone does not keep a follower off a leader that brakes hard: at 15 m/s with ρ =
//! 1 s it allows a 17 m gap to a standing car, which takes 14 m of braking at 8 m/s² after the
//! reaction (measured on `platoon_merge_50`, where cars in the zone stop behind the queue:
//! rear-end contacts with the first form alone, docs/parameters.md). The second assumes the
//! leader brakes no harder than b_max.
//!
//! ```text
//! ```
//!
//! g(τ) the predicted bumper gap to the car ahead in the same lane (which keeps its speed v_l),
//! b_max the vehicle's braking limit (≥ u_max: the safety constraint may brake harder than the
//! comfort bound). Past T the optimal profile holds its arrival speed (u(T) = 0).

/// The unconstrained energy-optimal profile from (t₀, p₀ = 0, v₀) to distance D at t₀ + T
/// (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyOptimalProfile {
    /// t₀ (s).
    pub start_s: f64,
    /// v₀ (m/s).
    pub start_speed_mps: f64,
    /// T = t_f − t₀ (s, > 0).
    pub duration_s: f64,
    /// α of u(τ) = α τ + β (m/s³).
    pub jerk_mps3: f64,
    /// β (m/s²).
    pub start_accel_mps2: f64,
}

impl EnergyOptimalProfile {
    /// The profile reaching `distance_m` ahead `duration_s` after `start_s`, starting at
    /// `start_speed_mps`; `None` unless `duration_s` > 0 and every input is finite.
    pub fn new(
        start_s: f64,
        start_speed_mps: f64,
        distance_m: f64,
        duration_s: f64,
    ) -> Option<Self> {
        let finite = [start_s, start_speed_mps, distance_m, duration_s]
            .iter()
            .all(|x| x.is_finite());
        if !finite || duration_s <= 0.0 {
            return None;
        }
        let t = duration_s;
        let alpha = 3.0 * (start_speed_mps * t - distance_m) / (t * t * t);
        Some(Self {
            start_s,
            start_speed_mps,
            duration_s,
            jerk_mps3: alpha,
            start_accel_mps2: -alpha * t,
        })
    }

    /// u at local time τ = t − t₀ (held at 0 past T).
    pub fn accel_mps2(&self, tau_s: f64) -> f64 {
        if tau_s >= self.duration_s {
            0.0
        } else {
            self.jerk_mps3 * tau_s + self.start_accel_mps2
        }
    }

    /// v at local time τ (constant past T).
    pub fn speed_mps(&self, tau_s: f64) -> f64 {
        let tau = tau_s.min(self.duration_s);
        0.5 * self.jerk_mps3 * tau * tau + self.start_accel_mps2 * tau + self.start_speed_mps
    }

    /// p − p₀ at local time τ (constant speed past T).
    pub fn distance_m(&self, tau_s: f64) -> f64 {
        let tau = tau_s.min(self.duration_s);
        let within = self.jerk_mps3 * tau.powi(3) / 6.0
            + 0.5 * self.start_accel_mps2 * tau * tau
            + self.start_speed_mps * tau;
        within + self.speed_mps(tau) * (tau_s - tau).max(0.0)
    }

    /// The constants (a, b, c, d) of u = a t + b, v = ½ a t² + b t + c,
    /// p = a t³/6 + b t²/2 + c t + d in absolute time t (p₀ = `start_position_m`).
    pub fn absolute(&self, start_position_m: f64) -> [f64; 4] {
        let (t0, alpha, beta, v0) = (
            self.start_s,
            self.jerk_mps3,
            self.start_accel_mps2,
            self.start_speed_mps,
        );
        let a = alpha;
        let b = beta - alpha * t0;
        // v(t) = ½α(t − t₀)² + β(t − t₀) + v₀ expanded.
        let c = 0.5 * alpha * t0 * t0 - beta * t0 + v0;
        // p(t) = α(t − t₀)³/6 + β(t − t₀)²/2 + v₀(t − t₀) + p₀ expanded.
        let d = -alpha * t0.powi(3) / 6.0 + 0.5 * beta * t0 * t0 - v0 * t0 + start_position_m;
        [a, b, c, d]
    }
}

/// The limits of the constrained profile (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileLimits {
    /// v_min (m/s).
    pub min_speed_mps: f64,
    /// v_max (m/s).
    pub max_speed_mps: f64,
    /// u_max (m/s²).
    pub max_accel_mps2: f64,
    /// b_max: hardest braking allowed for the rear-end constraint (m/s², positive).
    pub max_brake_mps2: f64,
    /// δ_safe (m).
    pub standstill_gap_m: f64,
    /// ρ (s).
    pub reaction_time_s: f64,
    /// h (s).
    pub step_s: f64,
}

/// The car ahead in the same lane: bumper gap now and its speed (kept constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leader {
    /// Bumper-to-bumper gap now (m).
    pub gap_m: f64,
    /// Its speed (m/s).
    pub speed_mps: f64,
}

/// One sample of the constrained profile: local time, distance travelled, speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileSample {
    /// τ (s).
    pub tau_s: f64,
    /// Distance from the start (m).
    pub distance_m: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
}

/// The highest speed at the end of the next step that keeps both forms of the rear-end
/// constraint (module doc) behind `leader`, having covered `s_m` at local time `tau_s`.
fn safe_speed_mps(limits: &ProfileLimits, leader: &Leader, tau_s: f64, s_m: f64) -> f64 {
    let h = limits.step_s;
    let rho = limits.reaction_time_s;
    let b = limits.max_brake_mps2;
    // Gap after the step, driven at v: g(τ) + v_l h − v h.
    let room_m = leader.gap_m + leader.speed_mps * (tau_s + h) - s_m - limits.standstill_gap_m;
    // g ≥ δ_safe + ρ v  ⇔  v ≤ (room) / (ρ + h).
    let time_gap_form = room_m / (rho + h);
    // g ≥ δ_safe + ρ v + v²/2b − v_l²/2b  ⇔  v²/2b + (ρ + h) v − (room + v_l²/2b) ≤ 0.
    let reach = room_m + leader.speed_mps * leader.speed_mps / (2.0 * b);
    let braking_form = if reach <= 0.0 {
        0.0
    } else {
        let t = rho + h;
        b * (-t + (t * t + 2.0 * reach / b).sqrt())
    };
    time_gap_form.min(braking_form).max(0.0)
}

/// The constrained profile (module doc) from speed `v0_mps`, integrated until `distance_m`
/// is covered or `max_steps` steps are taken. `desired(τ, s)` is the unconstrained speed wanted
/// at local time τ having covered s (the energy-optimal profile's speed, or another target
/// inside the merging zone).
pub fn constrained_profile(
    v0_mps: f64,
    limits: &ProfileLimits,
    leader: Option<Leader>,
    distance_m: f64,
    max_steps: usize,
    desired: &dyn Fn(f64, f64) -> f64,
) -> Vec<ProfileSample> {
    let h = limits.step_s;
    let mut out = vec![ProfileSample {
        tau_s: 0.0,
        distance_m: 0.0,
        speed_mps: v0_mps,
    }];
    let (mut tau, mut s, mut v) = (0.0, 0.0, v0_mps);
    for _ in 0..max_steps {
        if s >= distance_m {
            break;
        }
        let mut v_des = desired(tau + h, s)
            .max(limits.min_speed_mps)
            .min(limits.max_speed_mps);
        if let Some(l) = leader {
            v_des = v_des.min(safe_speed_mps(limits, &l, tau, s));
        }
        let v_next = v_des
            .max(v - limits.max_brake_mps2 * h)
            .min(v + limits.max_accel_mps2 * h)
            .max(0.0);
        // The step is driven at its end speed (explicit in the gap: the constraint written
        // with v(τ + h) holds exactly after the step whenever the braking bound allows it).
        s += v_next * h;
        tau += h;
        v = v_next;
        out.push(ProfileSample {
            tau_s: tau,
            distance_m: s,
            speed_mps: v,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: f64 = 1e-9;

    #[test]
    fn boundary_conditions_hold_in_the_hand_computed_case() {
        // From 15 m/s, 100 m in 8 s (cruising would take 6.67 s: it must slow down).
        // α = 3(15·8 − 100)/8³ = 60/512 = 0.1171875, β = −0.9375.
        let p = EnergyOptimalProfile::new(2.0, 15.0, 100.0, 8.0).unwrap();
        assert!((p.jerk_mps3 - 0.1171875).abs() < TOL);
        assert!((p.start_accel_mps2 + 0.9375).abs() < TOL);
        assert!(p.distance_m(0.0).abs() < TOL);
        assert!((p.speed_mps(0.0) - 15.0).abs() < TOL);
        assert!((p.distance_m(8.0) - 100.0).abs() < TOL);
        assert!(p.accel_mps2(8.0 - 1e-12).abs() < 1e-9);
        // v(T) = 1.5·100/8 − 0.5·15 = 11.25 m/s.
        assert!((p.speed_mps(8.0) - 11.25).abs() < TOL);
        // The 4×4 system in absolute time, t₀ = 2, t_f = 10, p₀ = 50.
        let [a, b, c, d] = p.absolute(50.0);
        let pos = |t: f64| a * t.powi(3) / 6.0 + b * t * t / 2.0 + c * t + d;
        let vel = |t: f64| a * t * t / 2.0 + b * t + c;
        assert!((pos(2.0) - 50.0).abs() < TOL);
        assert!((vel(2.0) - 15.0).abs() < TOL);
        assert!((pos(10.0) - 150.0).abs() < TOL);
        assert!((a * 10.0 + b).abs() < TOL);
    }

    #[test]
    fn the_optimum_has_lower_energy_than_another_feasible_profile() {
        // Constant deceleration reaching the same point at the same time (v free):
        // D = v₀T + ½ a T² ⇒ a = 2(D − v₀T)/T²; ∫u² = a² T.
        let p = EnergyOptimalProfile::new(0.0, 15.0, 100.0, 8.0).unwrap();
        let n = 80_000;
        let h = 8.0 / n as f64;
        let energy: f64 = (0..n)
            .map(|k| p.accel_mps2((k as f64 + 0.5) * h).powi(2) * h)
            .sum();
        let a_const = 2.0 * (100.0 - 15.0 * 8.0) / 64.0;
        assert!(energy < a_const * a_const * 8.0);
    }

    fn limits() -> ProfileLimits {
        ProfileLimits {
            min_speed_mps: 0.5,
            max_speed_mps: 20.0,
            max_accel_mps2: 3.0,
            max_brake_mps2: 8.0,
            standstill_gap_m: 2.0,
            reaction_time_s: 1.0,
            step_s: 0.01,
        }
    }

    #[test]
    fn the_constrained_profile_keeps_v_max_where_the_optimum_exceeds_it() {
        // From 18 m/s, 200 m in 8 s: v(T) = 1.5·200/8 − 9 = 28.5 m/s > v_max = 20.
        let p = EnergyOptimalProfile::new(0.0, 18.0, 200.0, 8.0).unwrap();
        assert!(p.speed_mps(8.0) > 20.0);
        let samples = constrained_profile(18.0, &limits(), None, 200.0, 10_000, &|tau, _| {
            p.speed_mps(tau)
        });
        let v_top = samples.iter().map(|s| s.speed_mps).fold(0.0, f64::max);
        assert!(v_top <= 20.0 + TOL, "{v_top}");
        // Far from the bound it follows the optimum.
        assert!((samples[1].speed_mps - p.speed_mps(0.01)).abs() < 1e-6);
    }

    #[test]
    fn it_stops_behind_a_standing_car_keeping_both_forms() {
        // From 20 m/s, a standing car 60 m ahead (both forms met: 60 ≥ 2 + 20 + 25). The
        // time-gap form alone would let it drive on at 20 m/s until the gap is 23 m, then ask
        // for 20 m/s² of braking (b_max = 8).
        let leader = Leader {
            gap_m: 60.0,
            speed_mps: 0.0,
        };
        let l = limits();
        let samples = constrained_profile(20.0, &l, Some(leader), 300.0, 3000, &|_, _| 20.0);
        for s in &samples {
            let gap = leader.gap_m - s.distance_m;
            let need = l.standstill_gap_m
                + l.reaction_time_s * s.speed_mps
                + s.speed_mps * s.speed_mps / (2.0 * l.max_brake_mps2);
            assert!(
                gap >= need - 1e-6,
                "τ {} gap {gap} v {}",
                s.tau_s,
                s.speed_mps
            );
        }
        let last = samples.last().map_or(f64::NAN, |s| s.speed_mps);
        assert!(last.abs() < 1e-6, "{last}");
    }

    #[test]
    fn the_rear_end_constraint_holds_behind_a_slower_leader() {
        // The optimum wants 15 m/s; the leader, 20 m ahead, drives at 10 m/s (the gap needed at
        // 15 m/s is 17 m: met at the start, lost within 0.6 s at constant speed).
        let leader = Leader {
            gap_m: 20.0,
            speed_mps: 10.0,
        };
        let l = limits();
        let samples = constrained_profile(15.0, &l, Some(leader), 300.0, 3000, &|_, _| 15.0);
        for s in &samples {
            let gap = leader.gap_m + leader.speed_mps * s.tau_s - s.distance_m;
            assert!(
                gap >= l.standstill_gap_m + l.reaction_time_s * s.speed_mps - 1e-9,
                "τ {} gap {gap} v {}",
                s.tau_s,
                s.speed_mps
            );
        }
        // Without the leader it would have kept 15 m/s.
        let free = constrained_profile(15.0, &l, None, 300.0, 3000, &|_, _| 15.0);
        assert!(free.iter().all(|s| (s.speed_mps - 15.0).abs() < TOL));
        // With it, it ends at the leader's speed.
        let last = samples.last().map_or(0.0, |s| s.speed_mps);
        assert!((last - 10.0).abs() < 0.05, "{last}");
    }
}
