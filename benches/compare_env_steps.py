#!/usr/bin/env python3
"""Environment steps per second: mergesim's MergeEnv beside highway-env's merge-v0, in one run.

Usage: python3 benches/compare_env_steps.py [--steps 300] [--reps 5] [--json PATH]

Needs, in the interpreter that runs it: the mergesim package (`pip install ./python`) and
highway-env 1.12.1 with gymnasium 1.4.0 (`pip install highway-env==1.12.1`), the versions this
script was written and run against.

What one step is, on each side (not the same model: a throughput comparison, not a
like-for-like one):
  * MergeEnv("urgent_merge"): one planning period, 0.1 s simulated: 50 physics steps of the
    two vehicles (tracking; tyre forces and a Rapier step with the default `rapier` vehicles,
    an RK4 step of CommonRoad's kinematic single track with `ks` vehicles, passed as
    params={"sim": {"vehicle_model": "ks"}}), the other vehicle's PF-ISO plan, V2V, safety and
    the observation and reward. The policy holds 20 m/s on the lane it is in (action [20, 0]).
  * highway-env merge-v0 (default config): one policy step, 1 s simulated: 15 kinematic steps
    of its 5 vehicles (IDM + MOBIL), the Kinematics observation and the reward; the policy is
    the IDLE action.
Both columns are given: steps per wall second and simulated seconds per wall second. Each
repetition times --steps steps of each environment (resetting on termination, the reset
included), interleaved (highway-env, mergesim rapier, mergesim ks, ...), after one untimed warm-up
step of each. Python start-up, imports and construction are excluded on both sides.
"""
import argparse
import json
import statistics
import sys
import time


def time_mergesim(steps, seed, vehicle_model="rapier"):
    import mergesim

    env = mergesim.MergeEnv("urgent_merge", params={"sim": {"vehicle_model": vehicle_model}})
    env.reset(seed=seed)
    env.step([20.0, 0.0])
    started = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step([20.0, 0.0])
        if terminated or truncated:
            env.reset(seed=seed)
    return time.perf_counter() - started


def time_highway_env(steps, seed):
    import gymnasium as gym
    import highway_env  # noqa: F401  (registers the environments)

    env = gym.make("merge-v0", render_mode=None)
    env.reset(seed=seed)
    idle = 1  # DiscreteMetaAction: IDLE
    env.step(idle)
    started = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(idle)
        if terminated or truncated:
            env.reset(seed=seed)
    return time.perf_counter() - started


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--json")
    args = ap.parse_args()
    if args.steps < 1 or args.reps < 1:
        sys.exit("--steps and --reps must be at least 1")
    samples = {"highway-env": [], "mergesim (rapier)": [], "mergesim (ks)": []}
    for rep in range(args.reps):
        samples["highway-env"].append(time_highway_env(args.steps, rep))
        samples["mergesim (rapier)"].append(time_mergesim(args.steps, rep, "rapier"))
        samples["mergesim (ks)"].append(time_mergesim(args.steps, rep, "ks"))
        print(f"repetition {rep + 1}/{args.reps}", file=sys.stderr)
    simulated_s_per_step = {"highway-env": 1.0, "mergesim (rapier)": 0.1, "mergesim (ks)": 0.1}
    print("| environment | steps/s (median, min–max) | simulated s per wall s (median) |")
    print("|---|---|---|")
    for name, walls in samples.items():
        rates = sorted(args.steps / w for w in walls)
        median = statistics.median(rates)
        print(f"| {name} | {median:,.0f} ({rates[0]:,.0f}–{rates[-1]:,.0f}) | "
              f"{median * simulated_s_per_step[name]:,.1f} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"steps": args.steps, "wall_s": samples}, f, indent=1)


if __name__ == "__main__":
    main()
