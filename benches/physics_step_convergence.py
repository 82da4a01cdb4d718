#!/usr/bin/env python3
"""How far the vehicle's validation trajectories move with the physics step.

The criterion of docs/parameters.md ("The physics step dt_s"): a step is small enough when every
trajectory of the vehicle validation manoeuvres stays within 2 % (of its largest absolute value)
of the same trajectory at dt = 1 ms. The trajectories (BMW 320i, μ = 0.8):

  - yaw rate, step steer 0.02 rad at 20 m/s      (`merge_sim maneuver step-steer`)
  - yaw rate, step steer 0.05 rad at 10 m/s
  - sideslip, step steer 0.02 rad at 20 m/s
  - speed, full braking from 20 m/s               (`merge_sim maneuver braking`)
  - speed, full braking from 5 m/s

each traced every --trace-period-s (default 0.02 s, a whole number of steps at every default
candidate) and compared at the trace times both runs have. Prints a Markdown table on stdout:
the largest deviation of each trajectory in % per step, and per step whether all stay within
2 %.

Usage:
  python3 benches/physics_step_convergence.py [--dt 0.002,0.0025,0.004,0.005,0.01,0.02]
                                              [--trace-period-s 0.02] [--bin PATH]

Needs a merge_sim binary (default target/release/merge_sim). Exit code 2 on bad usage, 1 if
merge_sim fails.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_common import log, parse_steps, provenance  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
REFERENCE_DT_S = 0.001
CRITERION_PERCENT = 2.0
# (label, maneuver, speed (m/s), steer (rad), traced field)
TRAJECTORIES = [
    ("yaw rate, step steer 0.02 rad at 20 m/s", "step-steer", 20.0, 0.02, "yaw_rate_radps"),
    ("yaw rate, step steer 0.05 rad at 10 m/s", "step-steer", 10.0, 0.05, "yaw_rate_radps"),
    ("sideslip, step steer 0.02 rad at 20 m/s", "step-steer", 20.0, 0.02, "sideslip_rad"),
    ("speed, full braking from 20 m/s", "braking", 20.0, 0.0, "speed_mps"),
    ("speed, full braking from 5 m/s", "braking", 5.0, 0.0, "speed_mps"),
]


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--dt", default="0.002,0.0025,0.004,0.005,0.01,0.02",
                   help="comma-separated physics steps in seconds, each in [0.0001, 0.02]")
    p.add_argument("--trace-period-s", type=float, default=0.02)
    p.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "merge_sim"))
    args = p.parse_args()
    try:
        args.steps = parse_steps(args.dt)
    except ValueError as e:
        p.error(f"--dt: {e}")
    if not (args.trace_period_s > 0.0):
        p.error("--trace-period-s must be > 0")
    if not os.access(args.bin, os.X_OK):
        p.error(f"--bin: {args.bin} is not an executable (cargo build --release --bin merge_sim)")
    return args


def trace(binary: str, tmp: str, maneuver: str, speed: float, steer: float, dt: float,
          period: float) -> dict[int, dict]:
    """The maneuver's trace, keyed by its time in whole microseconds."""
    out = os.path.join(tmp, "m.json")
    cmd = [binary, "maneuver", maneuver, "--vehicle", "bmw_320i", "--mu", "0.8", "--speed-mps", repr(speed),
           "--steer-rad", repr(steer), "--dt-s", repr(dt), "--trace-period-s", repr(period), "--json", out]
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"merge_sim failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr}")
    with open(out, encoding="utf-8") as f:
        report = json.load(f)
    return {round(s["t_s"] * 1e6): s["state"] for s in report["trace"]}


def largest_deviation_percent(ref: dict[int, dict], other: dict[int, dict], field: str) -> tuple[float, int]:
    """max |other − ref| over the common times, in % of max |ref|; and the number of times."""
    common = sorted(set(ref) & set(other))
    if not common:
        raise SystemExit("no common trace times: choose a --trace-period-s that is a whole number of every step")
    scale = max(abs(s[field]) for s in ref.values())
    worst = max(abs(other[t][field] - ref[t][field]) for t in common)
    return 100.0 * worst / scale, len(common)


def main() -> int:
    args = parse_args()
    info = provenance(ROOT, args.bin, {})
    tmp = tempfile.mkdtemp(prefix="mergesim-dt-convergence-")
    table: dict[str, dict[float, tuple[float, int]]] = {}
    for label, maneuver, speed, steer, field in TRAJECTORIES:
        log(f"{label} ...")
        ref = trace(args.bin, tmp, maneuver, speed, steer, REFERENCE_DT_S, args.trace_period_s)
        table[label] = {dt: largest_deviation_percent(
            ref, trace(args.bin, tmp, maneuver, speed, steer, dt, args.trace_period_s), field)
            for dt in args.steps}
    out = ["### Largest deviation of the validation trajectories from dt = 1 ms", ""]
    out.append(f"- date: {info['date']}; mergesim checkout {info['mergesim_commit'][:12]}"
               f"{' (dirty tree)' if info['mergesim_tree_dirty'] else ''}; binary {args.bin} "
               f"(built {info['merge_sim_binary_mtime']})")
    out.append(f"- BMW 320i, μ = 0.8; traces every {args.trace_period_s:g} s (rounded to whole steps), compared "
               f"at the times both runs have; % of the trajectory's largest absolute value at 1 ms; "
               f"criterion ≤ {CRITERION_PERCENT:g} % on every trajectory")
    out.append("")
    out.append("| trajectory | " + " | ".join(f"{dt * 1e3:g} ms" for dt in args.steps) + " |")
    out.append("|---|" + "---:|" * len(args.steps))
    for label, row in table.items():
        out.append(f"| {label} | " + " | ".join(f"{row[dt][0]:.2f} %" for dt in args.steps) + " |")
    passes = {dt: all(row[dt][0] <= CRITERION_PERCENT for row in table.values()) for dt in args.steps}
    out.append(f"| within {CRITERION_PERCENT:g} % on every trajectory | "
               + " | ".join("yes" if passes[dt] else "no" for dt in args.steps) + " |")
    fewest = min(n for row in table.values() for _, n in row.values())
    out.append("")
    out.append(f"Fewest common trace times in a comparison: {fewest}.")
    print("\n".join(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
