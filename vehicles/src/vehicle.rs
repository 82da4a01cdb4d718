//! A car as a rapier dynamic rigid body on four ray-cast wheels.
//!
//! The chassis is one rigid body whose origin is the CoG, with the total mass and the roll,
//! pitch and yaw inertias set explicitly (its box collider has zero density). Each step,
//! [`Vehicle::apply_forces`] resets the body's user forces (rapier keeps them otherwise), casts
//! the four wheel rays, runs the wheel model ([`crate::wheel`]) and adds every wheel's
//! suspension + tyre force at its contact point with `add_force_at_point`. Load transfer,
//! roll and pitch are therefore not modelled separately: they emerge from the rigid body
//! dynamics of forces acting at ground level below a CoG at `cog_height_m`.

use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, MassProperties, Pose, Ray, Real, RigidBodyBuilder,
    RigidBodyHandle, Rotation, Vector,
};

use crate::collision_groups;
use crate::controls::Controls;
use crate::error::VehicleError;
use crate::kinematics::Kinematics;
use crate::params::VehicleParams;
use crate::physics_world::PhysicsWorld;
use crate::tire::{TireCurves, slip_speed_floor_mps};
use crate::wheel::{
    Contact, WheelForces, WheelGeometry, WheelInputs, WheelState, WheelTelemetry, update_in_air,
    update_in_contact,
};

/// Friction coefficients accepted by [`Vehicle::try_apply_forces`].
pub const MU_RANGE: (f64, f64) = (0.01, 3.0);

/// Height above the spawn point from which the ground is searched (m).
const SPAWN_PROBE_HEIGHT_M: f64 = 50.0;

/// Below this horizontal speed the sideslip angle is reported as 0 (m/s).
const SIDESLIP_MIN_SPEED_MPS: f64 = 0.1;

/// Axis-aligned chassis box in the body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyBox {
    /// Half extents along body x, y, z (m).
    pub half_extents_m: [f64; 3],
    /// Centre of the box relative to the CoG, body frame (m). The box is centred on the
    /// wheelbase midpoint (equal overhangs; CommonRoad gives no overhangs).
    pub center_offset_m: [f64; 3],
}

impl BodyBox {
    /// The chassis box of a car of `params`: its length × width, from its ground clearance to
    /// its body height, centred on the wheelbase midpoint.
    pub fn of(params: &VehicleParams) -> Self {
        BodyBox {
            half_extents_m: [
                0.5 * params.length_m,
                0.5 * params.width_m,
                0.5 * (params.body_height_m - params.ground_clearance_m),
            ],
            center_offset_m: [
                0.5 * (params.cog_to_front_axle_m - params.cog_to_rear_axle_m),
                0.0,
                0.5 * (params.body_height_m + params.ground_clearance_m) - params.cog_height_m,
            ],
        }
    }
}

/// The road's height below a spawn pose (x, y, heading; road coordinates), after checking the
/// pose is finite and `speed_mps` finite and ≥ 0; errors name the field (`spawn.x_m`, …) or
/// say there is no road below.
pub(crate) fn spawn_ground_height_m(
    world: &mut PhysicsWorld,
    pose_m: [f64; 3],
    speed_mps: f64,
) -> Result<f64, VehicleError> {
    let [x_m, y_m, yaw_rad] = pose_m;
    for (name, value) in [("x_m", x_m), ("y_m", y_m), ("yaw_rad", yaw_rad)] {
        if !value.is_finite() {
            return Err(VehicleError::invalid(
                format!("spawn.{name}"),
                value,
                "must be finite",
            ));
        }
    }
    if !speed_mps.is_finite() || speed_mps < 0.0 {
        return Err(VehicleError::invalid(
            "spawn.speed_mps",
            speed_mps,
            "must be finite and >= 0",
        ));
    }
    world
        .ground_height_m(x_m, y_m, SPAWN_PROBE_HEIGHT_M)
        .ok_or(VehicleError::NoGround { x_m, y_m })
}

/// A simulated car.
pub struct Vehicle {
    params: VehicleParams,
    body: RigidBodyHandle,
    collider: ColliderHandle,
    geometry: [WheelGeometry; 4],
    wheels: [WheelState; 4],
    telemetry: [WheelTelemetry; 4],
    controls: Controls,
    steer_rad: f64,
    /// Chassis velocity when the last `apply_forces` ran (for the acceleration).
    previous_linvel_mps: [f64; 3],
    curves: TireCurves,
    body_box: BodyBox,
}

fn v3(v: Vector) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

fn to_vector(v: [f64; 3]) -> Vector {
    Vector::new(v[0] as Real, v[1] as Real, v[2] as Real)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(a, a).sqrt();
    (n > 1e-9).then(|| scale(a, 1.0 / n))
}

/// Rotates `v` by the unit quaternion (w, x, y, z) in f64.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let u = [x, y, z];
    let t = scale(cross(u, v), 2.0);
    add(add(v, scale(t, w)), cross(u, t))
}

fn quat(rotation: &Rotation) -> [f64; 4] {
    [
        f64::from(rotation.w),
        f64::from(rotation.x),
        f64::from(rotation.y),
        f64::from(rotation.z),
    ]
}

/// ZYX Euler angles (yaw, pitch, roll) of a unit quaternion (w, x, y, z).
fn euler_zyx(q: [f64; 4]) -> (f64, f64, f64) {
    let [w, x, y, z] = q;
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    (yaw, pitch, roll)
}

impl Vehicle {
    /// Inserts a car into `world` with its CoG above (x, y), heading `yaw_rad`, moving forward at
    /// `speed_mps`: settled on its springs (static loads, no bounce) and with its wheels spinning
    /// at road speed. Errors on invalid parameters or inputs, or if there is no road below.
    pub fn spawn(
        world: &mut PhysicsWorld,
        params: &VehicleParams,
        x_m: f64,
        y_m: f64,
        yaw_rad: f64,
        speed_mps: f64,
    ) -> Result<Vehicle, VehicleError> {
        params.validate()?;
        let ground_z = spawn_ground_height_m(world, [x_m, y_m, yaw_rad], speed_mps)?;
        // Rapier's coordinates are relative to the world's local origin.
        let [x_local_m, y_local_m] = world.to_local_m([x_m, y_m]);

        let g = world.gravity_mps2();
        let geometry = WheelGeometry::for_vehicle(params, g);
        let (s, c) = yaw_rad.sin_cos();
        let rotation = Rotation::from_rotation_z(yaw_rad as Real);
        let mass = MassProperties::new(
            Vector::ZERO,
            params.mass_kg as Real,
            Vector::new(
                params.roll_inertia_kgm2 as Real,
                params.pitch_inertia_kgm2 as Real,
                params.yaw_inertia_kgm2 as Real,
            ),
        );
        let body = RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(
                to_vector([x_local_m, y_local_m, ground_z + params.cog_height_m]),
                rotation,
            ))
            .linvel(to_vector([c * speed_mps, s * speed_mps, 0.0]))
            .additional_mass_properties(mass)
            .can_sleep(false)
            .build();
        let body_box = BodyBox::of(params);
        let collider = ColliderBuilder::cuboid(
            body_box.half_extents_m[0] as Real,
            body_box.half_extents_m[1] as Real,
            body_box.half_extents_m[2] as Real,
        )
        .translation(to_vector(body_box.center_offset_m))
        .density(0.0)
        .collision_groups(collision_groups::vehicle())
        .build();
        let rapier = world.rapier_mut();
        let body = rapier.insert_body(body);
        let collider = rapier.insert_collider(collider, Some(body));

        let spin = speed_mps / params.wheel_radius_m;
        let wheels = [WheelState {
            spin_radps: spin,
            lateral_slip_tan: 0.0,
        }; 4];
        Ok(Vehicle {
            params: params.clone(),
            body,
            collider,
            geometry,
            wheels,
            telemetry: [WheelTelemetry::default(); 4],
            controls: Controls::default(),
            steer_rad: 0.0,
            previous_linvel_mps: [c * speed_mps, s * speed_mps, 0.0],
            curves: TireCurves::new(&params.tire, 1.0),
            body_box,
        })
    }

    /// The vehicle's parameters.
    pub fn params(&self) -> &VehicleParams {
        &self.params
    }

    /// The chassis rigid body.
    pub fn chassis_handle(&self) -> RigidBodyHandle {
        self.body
    }

    /// The chassis box collider.
    pub fn collider_handle(&self) -> ColliderHandle {
        self.collider
    }

    /// Geometry of the chassis box collider in the body frame.
    pub fn body_box(&self) -> BodyBox {
        self.body_box
    }

    /// The planner's footprint of this car.
    pub fn shape(&self, max_brake_decel_mps2: f64) -> mergesim_types::VehicleShape {
        mergesim_types::VehicleShape {
            length_m: self.params.length_m,
            width_m: self.params.width_m,
            wheelbase_m: self.params.wheelbase_m(),
            max_brake_decel_mps2,
        }
    }

    /// The controls as clamped by [`set_controls`](Self::set_controls).
    pub fn controls(&self) -> Controls {
        self.controls
    }

    /// Per-wheel results of the last [`apply_forces`](Self::apply_forces) (FL, FR, RL, RR).
    pub fn wheel_telemetry(&self) -> [WheelTelemetry; 4] {
        self.telemetry
    }

    /// Sets the inputs, clamped to the physical limits: steering to ±`max_steer_rad` (the actual
    /// angle then follows at `max_steer_rate_radps`), drive torque to [0, the wheel's share of
    /// `max_drive_torque_nm`] (0 on non-driven wheels), brake torque to [0, the wheel's share of
    /// `max_brake_torque_nm`]. Non-finite torques become 0; a non-finite steering angle keeps the
    /// previous target.
    pub fn set_controls(&mut self, controls: Controls) {
        self.controls = controls.clamped(&self.params, self.controls.steer_rad);
    }

    /// Suspension and tyre forces for the coming step, at road friction `mu` (call once before
    /// each `world.step()`). An unusable μ is clamped into `MU_RANGE` (NaN → lowest); use
    /// [`try_apply_forces`](Self::try_apply_forces) to get an error instead. Does nothing if
    /// the chassis was removed from the world.
    pub fn apply_forces(&mut self, world: &mut PhysicsWorld, mu: f64) {
        let mu = if mu.is_nan() {
            MU_RANGE.0
        } else {
            mu.clamp(MU_RANGE.0, MU_RANGE.1)
        };
        let _ = self.try_apply_forces(world, mu);
    }

    /// [`apply_forces`](Self::apply_forces) that rejects μ outside `MU_RANGE` and reports a
    /// missing chassis.
    pub fn try_apply_forces(
        &mut self,
        world: &mut PhysicsWorld,
        mu: f64,
    ) -> Result<(), VehicleError> {
        if !(mu >= MU_RANGE.0 && mu <= MU_RANGE.1) {
            return Err(VehicleError::invalid(
                "mu",
                mu,
                format!("must lie in [{}, {}]", MU_RANGE.0, MU_RANGE.1),
            ));
        }
        if self.curves.mu.to_bits() != mu.to_bits() {
            self.curves = TireCurves::new(&self.params.tire, mu);
        }
        let dt = world.dt_s();
        let g = world.gravity_mps2();
        let local_origin_m = world.local_origin_m();
        let (translation, q, linvel, angvel, com) = {
            let body = world
                .bodies()
                .get(self.body)
                .ok_or(VehicleError::MissingBody)?;
            (
                v3(body.translation()),
                quat(body.rotation()),
                v3(body.linvel()),
                v3(body.angvel()),
                v3(body.center_of_mass()),
            )
        };
        self.previous_linvel_mps = linvel;

        // Steering actuator: rate-limited towards the target.
        let max_step = self.params.max_steer_rate_radps * dt;
        self.steer_rad += (self.controls.steer_rad - self.steer_rad).clamp(-max_step, max_step);

        let forward = rotate(q, [1.0, 0.0, 0.0]);
        let left = rotate(q, [0.0, 1.0, 0.0]);
        let up = rotate(q, [0.0, 0.0, 1.0]);
        let down = scale(up, -1.0);
        let (steer_sin, steer_cos) = self.steer_rad.sin_cos();
        let floor = slip_speed_floor_mps(&self.params.tire, dt, g);

        let mut applied: [Option<([f64; 3], [f64; 3])>; 4] = [None; 4];
        for (i, slot) in applied.iter_mut().enumerate() {
            let geometry = self.geometry[i];
            let inputs = WheelInputs {
                params: &self.params,
                curves: &self.curves,
                dt_s: dt,
                gravity_mps2: g,
                slip_speed_floor_mps: floor,
                drive_torque_nm: self.controls.drive_torque_nm[i],
                brake_torque_nm: self.controls.brake_torque_nm[i],
            };
            let origin = add(translation, rotate(q, geometry.hardpoint_m));
            let ray = Ray::new(to_vector(origin), to_vector(down));
            let hit = world.cast_road_ray(&ray, geometry.max_ray_length_m() as Real);
            let Some(hit) = hit else {
                update_in_air(&mut self.wheels[i], &inputs, &mut self.telemetry[i]);
                continue;
            };
            let toi = f64::from(hit.time_of_impact);
            let deflection = geometry.static_deflection_m + geometry.static_ray_length_m - toi;
            if deflection <= 0.0 {
                update_in_air(&mut self.wheels[i], &inputs, &mut self.telemetry[i]);
                continue;
            }
            let normal = normalize(v3(hit.normal)).unwrap_or(up);
            let contact_point = add(origin, scale(down, toi));
            let lever = sub(contact_point, com);
            let v_contact = add(linvel, cross(angvel, lever));
            let heading = if geometry.steered {
                add(scale(forward, steer_cos), scale(left, steer_sin))
            } else {
                forward
            };
            let Some(wheel_x) = normalize(sub(heading, scale(normal, dot(heading, normal)))) else {
                update_in_air(&mut self.wheels[i], &inputs, &mut self.telemetry[i]);
                continue;
            };
            let wheel_y = cross(normal, wheel_x);
            let contact = Contact {
                deflection_m: deflection,
                deflection_rate_mps: dot(v_contact, down),
                v_long_mps: dot(v_contact, wheel_x),
                v_lat_mps: dot(v_contact, wheel_y),
                normal_cos: dot(normal, up),
            };
            // Reported in the road's coordinates (Rapier's are relative to the local origin).
            self.telemetry[i].contact_point_m = [
                contact_point[0] + local_origin_m[0],
                contact_point[1] + local_origin_m[1],
                contact_point[2],
            ];
            let WheelForces {
                normal_load_n,
                fx_n,
                fy_n,
            } = update_in_contact(
                &geometry,
                &mut self.wheels[i],
                &contact,
                &inputs,
                &mut self.telemetry[i],
            );
            // The spring acts along the chassis axis, but the linkage carries its lateral
            // component: the road pushes along its normal with Fz (as in Bullet's ray-cast
            // vehicle). Pushing along the rolled chassis axis instead would add a lateral force
            // m·g·sin(roll) that the tyres must cancel (~20 % extra slip at 1.2 m/s²).
            let force = add(
                scale(normal, normal_load_n),
                add(scale(wheel_x, fx_n), scale(wheel_y, fy_n)),
            );
            *slot = Some((force, contact_point));
        }

        let body = world
            .bodies_mut()
            .get_mut(self.body)
            .ok_or(VehicleError::MissingBody)?;
        body.reset_forces(false);
        body.reset_torques(false);
        for (force, point) in applied.into_iter().flatten() {
            body.add_force_at_point(to_vector(force), to_vector(point), true);
        }
        Ok(())
    }

    /// Pose, velocities and accelerations of the CoG. Accelerations are the velocity change over
    /// the last step, so call this after `world.step()`. A missing chassis gives zeros.
    pub fn kinematics(&self, world: &PhysicsWorld) -> Kinematics {
        let Some(body) = world.bodies().get(self.body) else {
            return Kinematics::default();
        };
        let p = v3(body.translation());
        let q = quat(body.rotation());
        let v = v3(body.linvel());
        let w = v3(body.angvel());
        let (yaw, pitch, roll) = euler_zyx(q);
        let (s, c) = yaw.sin_cos();
        let vx = c * v[0] + s * v[1];
        let vy = -s * v[0] + c * v[1];
        let speed = v[0].hypot(v[1]);
        let dt = world.dt_s();
        let ax_w = (v[0] - self.previous_linvel_mps[0]) / dt;
        let ay_w = (v[1] - self.previous_linvel_mps[1]) / dt;
        let [x_m, y_m] = world.to_world_m([p[0], p[1]]);
        Kinematics {
            x_m,
            y_m,
            z_m: p[2],
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: roll,
            speed_mps: speed,
            vx_body_mps: vx,
            vy_body_mps: vy,
            yaw_rate_radps: w[2],
            sideslip_rad: if speed < SIDESLIP_MIN_SPEED_MPS {
                0.0
            } else {
                vy.atan2(vx)
            },
            accel_long_mps2: c * ax_w + s * ay_w,
            accel_lat_mps2: -s * ax_w + c * ay_w,
            steer_rad: self.steer_rad,
        }
    }
}
