#!/usr/bin/env python3
"""Reference trajectories of CommonRoad's vehicle models ks, st and std, for
`vehicles::commonroad_models`.

Writes tests/data/commonroad_models/reference.json (committed), which
vehicles/tests/commonroad_models.rs replays with the Rust models and compares state by state.

Reference package: commonroad-vehicle-models 3.0.2 (PyPI, BSD-3-Clause). Its derivative
functions (vehicle_dynamics_ks / _st / _std) and its parameter sets (setup_vehicle_parameters
1, 2, 3) are used as they are; only the time integration is written here, as the same fixed-step
classical Runge-Kutta (RK4) scheme the Rust side uses: the input is held over a step and
    x_next = x + dt/6 * (k1 + 2 k2 + 2 k3 + k4),
    k1 = f(x), k2 = f(x + dt/2 k1), k3 = f(x + dt/2 k2), k4 = f(x + dt k3).
Every call of a derivative function gets a fresh copy of its state list, because the package's
std model clamps the wheel speeds of the list it is handed (x[7], x[8] = max(0, .)).

    python3 -m venv /tmp/crvenv && /tmp/crvenv/bin/pip install commonroad-vehicle-models==3.0.2
    /tmp/crvenv/bin/python scripts/commonroad_models_reference.py           # rewrites the fixture
    /tmp/crvenv/bin/python scripts/commonroad_models_reference.py --check   # exit 1 if it differs

The fixture also holds the parameter values of vehicles 1-3 as the package reads them, so the
Rust test checks its constructors against them too.

Fixture layout: {"package": ..., "vehicles": {"1": {...}, ...}, "manoeuvres": [{"name", "model"
("ks" | "st" | "std"), "vehicle" (1 | 2 | 3), "dt_s", "record_every" (K), "initial_state"
(CommonRoad's state order), "segments": [{"steps", "steering_velocity_radps",
"acceleration_mps2"}], "states": [the state after 0, K, 2K, ... steps, and after the last step]}]}.
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
from importlib import metadata

from vehiclemodels.init_ks import init_ks
from vehiclemodels.init_st import init_st
from vehiclemodels.init_std import init_std
from vehiclemodels.vehicle_dynamics_ks import vehicle_dynamics_ks
from vehiclemodels.vehicle_dynamics_st import vehicle_dynamics_st
from vehiclemodels.vehicle_dynamics_std import vehicle_dynamics_std
from vehiclemodels.vehicle_parameters import setup_vehicle_parameters

PACKAGE = "commonroad-vehicle-models"
PACKAGE_VERSION = "3.0.2"
FIXTURE = (
    pathlib.Path(__file__).resolve().parent.parent
    / "tests"
    / "data"
    / "commonroad_models"
    / "reference.json"
)

DYNAMICS = {"ks": vehicle_dynamics_ks, "st": vehicle_dynamics_st, "std": vehicle_dynamics_std}

# The scalar parameters the three models read, by the package's names.
SCALARS = ["l", "w", "m", "I_z", "a", "b", "h_cg", "h_s", "I_y_w", "R_w", "T_sb", "T_se"]
STEERING = ["min", "max", "v_min", "v_max"]
LONGITUDINAL = ["v_min", "v_max", "v_switch", "a_max"]
TIRE = [
    "p_cx1", "p_dx1", "p_dx3", "p_ex1", "p_kx1", "p_hx1", "p_vx1",
    "r_bx1", "r_bx2", "r_cx1", "r_ex1", "r_hx1",
    "p_cy1", "p_dy1", "p_dy3", "p_ey1", "p_ky1", "p_hy1", "p_hy3", "p_vy1", "p_vy3",
    "r_by1", "r_by2", "r_by3", "r_cy1", "r_ey1", "r_hy1",
    "r_vy1", "r_vy3", "r_vy4", "r_vy5", "r_vy6",
]  # fmt: skip


def parameters_as_json(p) -> dict:
    return {
        **{k: float(getattr(p, k)) for k in SCALARS},
        "steering": {k: float(getattr(p.steering, k)) for k in STEERING},
        "longitudinal": {k: float(getattr(p.longitudinal, k)) for k in LONGITUDINAL},
        "tire": {k: float(getattr(p.tire, k)) for k in TIRE},
    }


def rk4_step(f, x: list[float], u: list[float], p, dt: float) -> list[float]:
    def deriv(state: list[float]) -> list[float]:
        return [float(v) for v in f(list(state), list(u), p)]

    k1 = deriv(x)
    k2 = deriv([xi + 0.5 * dt * ki for xi, ki in zip(x, k1)])
    k3 = deriv([xi + 0.5 * dt * ki for xi, ki in zip(x, k2)])
    k4 = deriv([xi + dt * ki for xi, ki in zip(x, k3)])
    return [
        xi + dt / 6.0 * (a + 2.0 * b + 2.0 * c + d)
        for xi, a, b, c, d in zip(x, k1, k2, k3, k4)
    ]


def initial_state(model: str, p, sx, sy, delta, v, psi, yaw_rate=0.0, beta=0.0) -> list[float]:
    """CommonRoad's own initialisation (init_ks / init_st / init_std) of a core state."""
    core = [sx, sy, delta, v, psi, yaw_rate, beta]
    if model == "ks":
        return [float(v) for v in init_ks(core[:5])]
    if model == "st":
        return [float(v) for v in init_st(core)]
    return [float(v) for v in init_std(core, p)]


def seg(steps: int, steering_velocity: float, acceleration: float) -> dict:
    return {
        "steps": steps,
        "steering_velocity_radps": steering_velocity,
        "acceleration_mps2": acceleration,
    }


def slalom(half_steps: int, steering_velocity: float, acceleration: float = 0.0) -> list[dict]:
    """Steering velocity +s, -s, +s, -s, +s for half, 2 half, 2 half, 2 half, half steps."""
    s = steering_velocity
    return [
        seg(half_steps, s, acceleration),
        seg(2 * half_steps, -s, acceleration),
        seg(2 * half_steps, s, acceleration),
        seg(2 * half_steps, -s, acceleration),
        seg(half_steps, s, acceleration),
    ]


def manoeuvres() -> list[dict]:
    """(name, model, vehicle, dt, K, initial core state, segments). Speeds in m/s, angles in rad.

    Steering-velocity inputs of 1 rad/s are above every vehicle's limit (0.4 rad/s), so the
    constraint clamps them; accelerations of 20 m/s^2 are above a_max (11.5 m/s^2). Initial
    steering angles like 0.0123 rad keep a limit crossing away from an RK4 stage instant.
    """
    m = []
    # --- ks (reference point: rear axle) ---
    m.append(("ks_full_throttle", "ks", 2, 0.01, 10, (0, 0, 0, 2.0, 0), [seg(400, 0.0, 20.0)]))
    m.append(("ks_constant_steering", "ks", 2, 0.01, 10, (0, 0, 0, 10.0, 0.3),
              [seg(100, 0.2, 0.0), seg(300, 0.0, 0.0)]))  # fmt: skip
    m.append(("ks_braking_to_stop", "ks", 1, 0.01, 10, (5, -2, 0.05, 15.0, 0),
              [seg(300, 0.0, -5.0), seg(100, 0.0, 0.0)]))  # fmt: skip
    m.append(("ks_slalom_steering_rate_limit", "ks", 3, 0.01, 10, (0, 0, 0, 15.0, 0),
              slalom(50, 1.0)))  # fmt: skip
    m.append(("ks_steer_to_angle_limit", "ks", 2, 0.01, 10, (0, 0, 0.0123, 3.0, 0),
              [seg(300, 1.0, 0.0), seg(50, -0.3, 0.0)]))  # fmt: skip
    m.append(("ks_reverse_to_speed_limit", "ks", 2, 0.01, 10, (0, 0, -0.1, -10.0, 0),
              [seg(400, 0.0, -20.0)]))  # fmt: skip
    # --- st (reference point: centre of mass) ---
    m.append(("st_constant_steering", "st", 2, 0.01, 10, (0, 0, 0, 15.0, 0),
              [seg(25, 0.4, 0.0), seg(375, 0.0, 0.0)]))  # fmt: skip
    m.append(("st_slalom_steering_rate_limit", "st", 2, 0.01, 10, (0, 0, 0, 20.0, 0),
              slalom(50, 1.0)))  # fmt: skip
    m.append(("st_accelerating_turn", "st", 1, 0.01, 10, (0, 0, 0.0, 8.0, 0),
              [seg(50, 0.2, 3.0), seg(350, 0.0, 20.0)]))  # fmt: skip
    m.append(("st_braking_in_a_turn", "st", 3, 0.01, 10, (0, 0, 0.03, 20.0, 0.5),
              [seg(400, 0.0, -4.0)]))  # fmt: skip
    # Through the switch to the kinematic model (|v| < 0.1 m/s); the dynamic model is stiff near
    # that speed (its beta equation has a 1/v term), hence the short step.
    m.append(("st_braking_to_stop", "st", 2, 0.001, 100, (0, 0, 0.05, 2.0, 0),
              [seg(1870, 0.05, -1.0), seg(600, 0.05, -0.07), seg(600, -0.1, 0.0)]))  # fmt: skip
    # --- std (Pacejka tyres and wheel speeds; the wheel dynamics are stiff: step 1 ms) ---
    # The spinning rear wheel's slip-induced side force turns the car without steering; the
    # run stops at 1.6 s, before the front wheel stalls sideways (past that the trajectory
    # amplifies a 1e-12 change of the initial speed beyond the test's tolerance).
    m.append(("std_full_throttle_wheel_spin", "std", 2, 0.001, 100, (0, 0, 0, 5.0, 0),
              [seg(1600, 0.0, 20.0)]))  # fmt: skip
    m.append(("std_high_mu_turn", "std", 2, 0.001, 100, (0, 0, 0, 20.0, 0),
              [seg(150, 0.4, 0.0), seg(1850, 0.0, 0.0)]))  # fmt: skip
    m.append(("std_limit_turn_under_braking", "std", 1, 0.001, 100, (0, 0, 0.0, 25.0, 0),
              [seg(250, 0.4, -6.0), seg(1250, 0.0, -6.0)]))  # fmt: skip
    m.append(("std_slalom_steering_rate_limit", "std", 3, 0.001, 100, (0, 0, 0, 15.0, 0),
              slalom(500, 1.0, 1.0)))  # fmt: skip
    # Down through the blend with the kinematic model (0.2 m/s +- 0.05 m/s) to a stop.
    m.append(("std_braking_to_stop", "std", 2, 0.0001, 1000, (0, 0, 0.04, 1.5, 0),
              [seg(13700, 0.02, -1.0), seg(6300, 0.0, -0.02)]))  # fmt: skip
    return m


def run(name, model, vehicle, dt, every, core, segments) -> dict:
    p = setup_vehicle_parameters(vehicle_id=vehicle)
    x = initial_state(model, p, *[float(c) for c in core])
    f = DYNAMICS[model]
    states = [list(x)]
    n = 0
    for s in segments:
        u = [s["steering_velocity_radps"], s["acceleration_mps2"]]
        for _ in range(s["steps"]):
            x = rk4_step(f, x, u, p, dt)
            n += 1
            if n % every == 0:
                states.append(list(x))
    if n % every != 0:
        states.append(list(x))
    for row in states:
        if not all(math.isfinite(v) for v in row):
            raise SystemExit(f"{name}: a state is not finite: {row}")
    return {
        "name": name,
        "model": model,
        "vehicle": vehicle,
        "dt_s": dt,
        "record_every": every,
        "initial_state": states[0],
        "segments": segments,
        "states": states,
    }


def build() -> dict:
    version = metadata.version(PACKAGE)
    if version != PACKAGE_VERSION:
        raise SystemExit(f"{PACKAGE} {version} installed, the fixture is for {PACKAGE_VERSION}")
    return {
        "package": f"{PACKAGE} {version}",
        "generated_by": "scripts/commonroad_models_reference.py",
        "vehicles": {
            str(i): parameters_as_json(setup_vehicle_parameters(vehicle_id=i)) for i in (1, 2, 3)
        },
        "manoeuvres": [run(*m) for m in manoeuvres()],
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if the fixture differs")
    args = ap.parse_args()
    text = json.dumps(build(), indent=1) + "\n"
    if args.check:
        old = FIXTURE.read_text() if FIXTURE.exists() else ""
        if old != text:
            print(f"{FIXTURE} differs from what the script computes", file=sys.stderr)
            return 1
        print(f"{FIXTURE} is up to date")
        return 0
    FIXTURE.parent.mkdir(parents=True, exist_ok=True)
    FIXTURE.write_text(text)
    print(f"wrote {FIXTURE} ({len(text)} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
