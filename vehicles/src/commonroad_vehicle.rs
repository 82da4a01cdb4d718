//! [`CommonRoadVehicle`]: a car moved by one of CommonRoad's vehicle models (its doc says how).
use crate::commonroad_models::{
    CommonRoadInput, CommonRoadVehicleParams, KsState, StState, StdState, ks_step_rk4, st_step_rk4,
    std_step_rk4,
};
use crate::controls::Controls;
use crate::error::VehicleError;
use crate::kinematic_body::KinematicBox;
use crate::kinematics::Kinematics;
use crate::params::VehicleParams;
use crate::physics_world::PhysicsWorld;
use crate::vehicle::{BodyBox, MU_RANGE, spawn_ground_height_m};
use crate::vehicle_model::VehicleModel;

mod car_params;
mod model_choice;
mod slip_control;

pub use model_choice::{CommonRoadIntegration, CommonRoadModel};
use slip_control::WheelSlipControl;

/// Below this speed the sideslip angle is reported as 0 (m/s), as for a `rapier` car.
const SIDESLIP_MIN_SPEED_MPS: f64 = 0.1;

/// The state of the model that moves the car, in CommonRoad's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommonRoadModelState {
    /// ks: the rear axle's position and speed.
    Ks(KsState),
    /// st: the centre of gravity's.
    St(StState),
    /// std: the centre of gravity's, with the wheel spins.
    Std(StdState),
}

/// A car moved by one of CommonRoad's vehicle models (`ks`, `st`, `std`) instead of Rapier's
/// rigid-body dynamics: the [`VehicleModel`] of the `ks`, `st` and `std` names.
///
/// **The car.** The model reads the car's own figures ([`VehicleParams`], the same preset as a
/// `rapier` car): mass, yaw inertia, axle distances, CoG height (also as the sprung mass's
/// height h_s, which mergesim's parameters do not separate), wheel radius and inertia, torque
/// shares, the steering-angle and steering-rate limits, and the Magic-Formula tyre (the
/// presets' tyre is CommonRoad's; the camber terms and the slip-ratio side force `r_vy*`,
/// which mergesim's tyre does not have, are CommonRoad's). On a road of friction μ:
/// - the tyre's peak coefficients are μ (`p_dx1 = p_dy1 = μ`, as the `rapier` tyre's
///   D = μ·F_z), so the st model's axle cornering stiffness is −`p_ky1`·F_z whatever μ;
/// - the acceleration limit a_max is the car's drive/brake limit (max torque / (R_w·m)),
///   and for `ks` and `st`, whose longitudinal motion has no tyre, also at most μ·g;
/// - no power limit (v_S = v_max = 100 m/s) and no reversing (v_min = 0: a braking car stops,
///   and a speed the RK4 step leaves below 0 is set to 0).
///
/// **Inputs.** The tracker's [`Controls`], clamped to the car's limits as for a `rapier` car,
/// become CommonRoad's inputs: the steering velocity (δ_cmd − δ)/Δt that reaches the commanded
/// angle in one physics step, within ±`max_steer_rate_radps` (the `rapier` car's steering
/// actuator follows at the same rate), and the longitudinal acceleration
/// (Σ drive torque − Σ brake torque) / (R_w·m). Both are held over the physics step and
/// constrained inside the model ([`crate::commonroad_models::constraints`]).
///
/// **Integration.** RK4 sub-steps no longer than [`CommonRoadIntegration`]'s for the model (the
/// st sideslip and the std wheel-spin modes are stiff at low speed; step sizes in
/// [`crate::commonroad_models::integrate`]).
///
/// **ABS and traction control** (std only, where the car's `abs_enabled` /
/// `traction_control_enabled` say so, as on every preset): ideal, as on the `rapier` car. After
/// each sub-step a braked wheel is held at the tyre's peak braking slip and a driven wheel at its
/// peak driving slip. CommonRoad's model has neither; without them a full brake locks the
/// wheels and CommonRoad's tyre (its slip-ratio side force) spins the car.
///
/// **In the world.** The pose goes to a Rapier kinematic box ([`KinematicBox`]) of the
/// chassis' size, so a `rapier` car that touches it is pushed; the box is never pushed back, and
/// two kinematic boxes pass through each other: the simulator's safety checks find every
/// contact from the bodies' boxes, not from Rapier's contacts. The road is taken as flat at
/// the spawn point's height (no pitch, roll or suspension).
///
/// **Kinematics.** The centre of gravity's state: ks's rear-axle state is moved to the CoG
/// (position + l_r along the heading; body velocities v and v·l_r·tan δ / L; yaw rate
/// v·tan δ / L); st's and std's state is the CoG's (v_x = v cos β, v_y = v sin β).
/// Accelerations are the change of the body-frame velocity over the step plus the rotation of
/// the frame: a_x = Δv_x/Δt − v_y·ψ̇, a_y = Δv_y/Δt + v_x·ψ̇.
pub struct CommonRoadVehicle {
    model: CommonRoadModel,
    params: VehicleParams,
    /// The car in CommonRoad's terms at `model_mu` (rebuilt when the road's μ changes).
    model_params: CommonRoadVehicleParams,
    model_mu: f64,
    integration: CommonRoadIntegration,
    /// The std car's ABS and traction control at `model_mu`.
    slip_control: Option<WheelSlipControl>,
    state: CommonRoadModelState,
    controls: Controls,
    body: KinematicBox,
    body_box: BodyBox,
    /// Height of the CoG above the road's z = 0 (m).
    cog_z_m: f64,
    /// The CoG's kinematics after the last step.
    current: Kinematics,
}

impl CommonRoadVehicle {
    /// Spawns a car of `params` moved by `model` with its CoG at (`x_m`, `y_m`) heading
    /// `yaw_rad`, rolling straight at `speed_mps`, with its kinematic box in `world`. Errors on
    /// invalid parameters, non-finite pose, negative speed or no road below the spawn point.
    pub fn spawn(
        world: &mut PhysicsWorld,
        model: CommonRoadModel,
        params: &VehicleParams,
        integration: CommonRoadIntegration,
        pose_m: [f64; 3],
        speed_mps: f64,
    ) -> Result<Self, VehicleError> {
        params.validate()?;
        integration.validate()?;
        let ground_z_m = spawn_ground_height_m(world, pose_m, speed_mps)?;
        let mu = 1.0;
        let model_params = CommonRoadVehicleParams::from_vehicle_params(params, model, mu);
        model_params.validate()?;
        let state = initial_state(model, &model_params, pose_m, speed_mps);
        let body_box = BodyBox::of(params);
        let body = KinematicBox::spawn(
            world,
            params.length_m,
            params.width_m,
            params.ground_clearance_m,
            params.body_height_m,
            box_pose_m(pose_m, &body_box),
        )?;
        let mut vehicle = Self {
            model,
            params: params.clone(),
            model_params,
            model_mu: mu,
            integration,
            slip_control: WheelSlipControl::of(params, mu),
            state,
            controls: Controls::default(),
            body,
            body_box,
            cog_z_m: ground_z_m + params.cog_height_m,
            current: Kinematics::default(),
        };
        vehicle.current = vehicle.kinematics_of(&state, None, 0.0);
        Ok(vehicle)
    }

    /// The model that moves the car.
    pub fn model(&self) -> CommonRoadModel {
        self.model
    }

    /// The model's state now.
    pub fn state(&self) -> CommonRoadModelState {
        self.state
    }

    /// The car in CommonRoad's terms, as the model reads it now.
    pub fn model_params(&self) -> &CommonRoadVehicleParams {
        &self.model_params
    }

    /// The kinematic box that stands for the car in the physics world.
    pub fn body(&self) -> KinematicBox {
        self.body
    }

    /// CommonRoad's input for the coming step of `dt_s` from the clamped controls.
    fn input(&self, dt_s: f64) -> CommonRoadInput {
        let steer_rad = steering_angle_rad(&self.state);
        let c = &self.controls;
        let net_torque_nm: f64 =
            c.drive_torque_nm.iter().sum::<f64>() - c.brake_torque_nm.iter().sum::<f64>();
        CommonRoadInput {
            steering_velocity_radps: (c.steer_rad - steer_rad) / dt_s,
            acceleration_mps2: net_torque_nm / (self.params.wheel_radius_m * self.params.mass_kg),
        }
    }

    /// The number of equal RK4 sub-steps of a physics step of `dt_s`.
    fn substeps(&self, dt_s: f64) -> usize {
        let i = &self.integration;
        let max_s = match self.state {
            CommonRoadModelState::Ks(_) => i.ks_max_substep_s,
            CommonRoadModelState::St(_) => i.st_max_substep_s,
            CommonRoadModelState::Std(x) if x.speed_mps < i.std_slow_speed_mps => {
                i.std_slow_max_substep_s
            }
            CommonRoadModelState::Std(_) => i.std_max_substep_s,
        };
        // At least one; at most a million (a validated step cannot ask for more).
        (dt_s / max_s).ceil().clamp(1.0, 1e6) as usize
    }

    /// The CoG's kinematics in `state`, with the accelerations from `previous` over `dt_s`.
    fn kinematics_of(
        &self,
        state: &CommonRoadModelState,
        previous: Option<&Kinematics>,
        dt_s: f64,
    ) -> Kinematics {
        let p = &self.model_params;
        let (x_m, y_m, yaw_rad, vx, vy, yaw_rate, steer) = match *state {
            CommonRoadModelState::Ks(s) => {
                let wheelbase_m = p.wheelbase_m();
                let (sin, cos) = s.yaw_rad.sin_cos();
                let tan = s.steering_angle_rad.tan();
                (
                    s.x_m + p.cog_to_rear_axle_m * cos,
                    s.y_m + p.cog_to_rear_axle_m * sin,
                    s.yaw_rad,
                    s.speed_mps,
                    s.speed_mps * p.cog_to_rear_axle_m * tan / wheelbase_m,
                    s.speed_mps * tan / wheelbase_m,
                    s.steering_angle_rad,
                )
            }
            CommonRoadModelState::St(s) => st_like(
                s.x_m,
                s.y_m,
                s.yaw_rad,
                s.speed_mps,
                s.slip_angle_rad,
                s.yaw_rate_radps,
                s.steering_angle_rad,
            ),
            CommonRoadModelState::Std(s) => st_like(
                s.x_m,
                s.y_m,
                s.yaw_rad,
                s.speed_mps,
                s.slip_angle_rad,
                s.yaw_rate_radps,
                s.steering_angle_rad,
            ),
        };
        let speed_mps = vx.hypot(vy);
        let (accel_long_mps2, accel_lat_mps2) = match previous {
            Some(k) if dt_s > 0.0 => (
                (vx - k.vx_body_mps) / dt_s - vy * yaw_rate,
                (vy - k.vy_body_mps) / dt_s + vx * yaw_rate,
            ),
            _ => (0.0, 0.0),
        };
        Kinematics {
            x_m,
            y_m,
            z_m: self.cog_z_m,
            yaw_rad: mergesim_types::angle::wrap_angle_rad(yaw_rad),
            pitch_rad: 0.0,
            roll_rad: 0.0,
            speed_mps,
            vx_body_mps: vx,
            vy_body_mps: vy,
            yaw_rate_radps: yaw_rate,
            sideslip_rad: if speed_mps < SIDESLIP_MIN_SPEED_MPS {
                0.0
            } else {
                vy.atan2(vx)
            },
            accel_long_mps2,
            accel_lat_mps2,
            steer_rad: steer,
        }
    }
}

/// Pose, body velocities, yaw rate and steering angle of an st or std state (CoG).
fn st_like(
    x_m: f64,
    y_m: f64,
    yaw_rad: f64,
    speed_mps: f64,
    slip_angle_rad: f64,
    yaw_rate_radps: f64,
    steer_rad: f64,
) -> (f64, f64, f64, f64, f64, f64, f64) {
    let (sin_b, cos_b) = slip_angle_rad.sin_cos();
    (
        x_m,
        y_m,
        yaw_rad,
        speed_mps * cos_b,
        speed_mps * sin_b,
        yaw_rate_radps,
        steer_rad,
    )
}

/// The front-wheel steering angle of a state (rad).
fn steering_angle_rad(state: &CommonRoadModelState) -> f64 {
    match state {
        CommonRoadModelState::Ks(s) => s.steering_angle_rad,
        CommonRoadModelState::St(s) => s.steering_angle_rad,
        CommonRoadModelState::Std(s) => s.steering_angle_rad,
    }
}

/// The model's state for a car with its CoG at `pose_m`, rolling straight at `speed_mps`.
fn initial_state(
    model: CommonRoadModel,
    p: &CommonRoadVehicleParams,
    pose_m: [f64; 3],
    speed_mps: f64,
) -> CommonRoadModelState {
    let [x_m, y_m, yaw_rad] = pose_m;
    let st = StState {
        x_m,
        y_m,
        steering_angle_rad: 0.0,
        speed_mps,
        yaw_rad,
        yaw_rate_radps: 0.0,
        slip_angle_rad: 0.0,
    };
    match model {
        CommonRoadModel::Ks => {
            let (sin, cos) = yaw_rad.sin_cos();
            CommonRoadModelState::Ks(KsState {
                x_m: x_m - p.cog_to_rear_axle_m * cos,
                y_m: y_m - p.cog_to_rear_axle_m * sin,
                steering_angle_rad: 0.0,
                speed_mps,
                yaw_rad,
            })
        }
        CommonRoadModel::St => CommonRoadModelState::St(st),
        CommonRoadModel::Std => CommonRoadModelState::Std(StdState::rolling(&st, p)),
    }
}

/// The box centre's pose for a CoG pose (x, y, heading).
fn box_pose_m(cog_pose_m: [f64; 3], body_box: &BodyBox) -> [f64; 3] {
    let [x, y, yaw] = cog_pose_m;
    let [ox, oy, _] = body_box.center_offset_m;
    let (s, c) = yaw.sin_cos();
    [x + ox * c - oy * s, y + ox * s + oy * c, yaw]
}

/// One physics step of `dt_s` of `state` in `n` RK4 sub-steps, the input held; a speed left
/// below zero is set to zero (no reversing), with the std wheels' spins.
fn integrate(
    state: CommonRoadModelState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
    dt_s: f64,
    n: usize,
    slip_control: Option<&WheelSlipControl>,
) -> CommonRoadModelState {
    let h = dt_s / n as f64;
    match state {
        CommonRoadModelState::Ks(mut s) => {
            for _ in 0..n {
                s = ks_step_rk4(&s, input, p, h);
            }
            s.speed_mps = s.speed_mps.max(0.0);
            CommonRoadModelState::Ks(s)
        }
        CommonRoadModelState::St(mut s) => {
            for _ in 0..n {
                s = st_step_rk4(&s, input, p, h);
            }
            s.speed_mps = s.speed_mps.max(0.0);
            CommonRoadModelState::St(s)
        }
        CommonRoadModelState::Std(mut s) => {
            for _ in 0..n {
                s = std_step_rk4(&s, input, p, h);
                if let Some(slip) = slip_control {
                    s = slip.hold(s, input.acceleration_mps2, p);
                }
            }
            s.speed_mps = s.speed_mps.max(0.0);
            s.front_wheel_speed_radps = s.front_wheel_speed_radps.max(0.0);
            s.rear_wheel_speed_radps = s.rear_wheel_speed_radps.max(0.0);
            CommonRoadModelState::Std(s)
        }
    }
}

impl VehicleModel for CommonRoadVehicle {
    fn model_name(&self) -> &str {
        self.model.name()
    }

    fn params(&self) -> &VehicleParams {
        &self.params
    }

    fn body_box(&self) -> BodyBox {
        self.body_box
    }

    fn kinematics(&self, _world: &PhysicsWorld) -> Kinematics {
        self.current
    }

    fn set_controls(&mut self, controls: Controls) {
        self.controls = controls.clamped(&self.params, self.controls.steer_rad);
    }

    /// The model moves the car itself; its box follows for contacts with rigid bodies only.
    fn needs_physics_step(&self) -> bool {
        false
    }

    /// Integrates the model over the coming physics step and sets the box's next pose. An
    /// unusable μ is taken into `MU_RANGE` (NaN → lowest), as for a `rapier` car.
    fn advance(&mut self, world: &mut PhysicsWorld, mu: f64) {
        let mu = if mu.is_nan() {
            MU_RANGE.0
        } else {
            mu.clamp(MU_RANGE.0, MU_RANGE.1)
        };
        if mu != self.model_mu {
            self.model_params =
                CommonRoadVehicleParams::from_vehicle_params(&self.params, self.model, mu);
            self.slip_control = WheelSlipControl::of(&self.params, mu);
            self.model_mu = mu;
        }
        let dt_s = world.dt_s();
        let input = self.input(dt_s);
        let n = self.substeps(dt_s);
        let next = integrate(
            self.state,
            &input,
            &self.model_params,
            dt_s,
            n,
            self.slip_control.as_ref(),
        );
        let kin = self.kinematics_of(&next, Some(&self.current), dt_s);
        self.state = next;
        self.current = kin;
        self.body.set_next_pose(
            world,
            box_pose_m([kin.x_m, kin.y_m, kin.yaw_rad], &self.body_box),
        );
    }
}
