#!/usr/bin/env python3
"""At which physics steps is mergesim's Rapier vehicle still valid?

For each candidate step dt (default: 0.02, 0.01, 0.005, 0.0025 and 0.002 s: MetaDrive's Bullet
step down to the simulator's default), two checks, neither of which measures speed:

1. The vehicle validation tests, unchanged, with every maneuver at dt
   (`MERGESIM_VALIDATION_DT_S=dt cargo test --release --test steady_state --test braking`):
   steady-state cornering against the linear single-track model (yaw rate within 10 % below
   2 m/s², sideslip, roll against the quasi-static roll equation, lateral acceleration capped
   near μ·g) and straight-line braking against v²/(2μg) (ABS) and against the Magic Formula's
   sliding friction (locked wheels). Every preset vehicle.
2. The closed loop at dt: the platoon of `merge_sim scenario platoon --vehicles N` (the
   MetaDrive comparison's, benches/compare_metadrive.sh), its nominal run and the randomised
   instances of `merge_sim sweep --runs K --seed 42`: every run completes, without a contact
   and without a fallback plan. Where the default safety-check period (0.01 s) is shorter than
   dt, the checks run every step (bench_common.with_physics_step).

A step is **valid** when both hold; the coarsest valid step is the largest candidate that is
valid together with every finer candidate. Prints a Markdown table on stdout (progress on stderr): per
step, the validation tests passed / run and the first line of each failure's message, the
closed loop's runs, contacts and fallback plans; then the coarsest valid step.

Usage:
  python3 benches/physics_step_validity.py [--dt 0.02,0.01,0.005,0.0025,0.002] [--vehicles N]
                                           [--sweep-runs K] [--bin PATH] [--json PATH]

Needs cargo (the tests are built with `cargo test --release`) and a merge_sim binary (default
target/release/merge_sim, built with `cargo build --release --bin merge_sim` if missing).
Exit code 2 on bad usage, 1 if a tool cannot run (a test binary that does not build, a
merge_sim that fails on a well-formed scenario).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_common import log, parse_steps, provenance, with_physics_step  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
DT_ENV = "MERGESIM_VALIDATION_DT_S"
DEFAULT_STEPS = "0.02,0.01,0.005,0.0025,0.002"


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--dt", default=DEFAULT_STEPS,
                   help=f"comma-separated physics steps in seconds (default {DEFAULT_STEPS})")
    p.add_argument("--vehicles", type=int, default=10, help="platoon size (default 10)")
    p.add_argument("--sweep-runs", type=int, default=4, help="randomised platoon instances (default 4)")
    p.add_argument("--bin", default=None, help="merge_sim binary (default target/release/merge_sim)")
    p.add_argument("--json", dest="json_path", default=None, help="also write the results as JSON")
    args = p.parse_args()
    try:
        args.steps = parse_steps(args.dt)
    except ValueError as e:
        p.error(f"--dt: {e}")
    if args.vehicles < 1 or args.sweep_runs < 1:
        p.error("--vehicles and --sweep-runs must be positive")
    if args.bin is None:
        args.bin = os.path.join(ROOT, "target", "release", "merge_sim")
        if not os.access(args.bin, os.X_OK):
            log("building merge_sim (release) ...")
            subprocess.run(["cargo", "build", "--release", "--bin", "merge_sim"], cwd=ROOT, check=True,
                           stdout=sys.stderr)
    if not os.access(args.bin, os.X_OK):
        p.error(f"--bin: {args.bin} is not an executable")
    return args


def validation_tests(dt: float) -> dict:
    """Runs the validation tests with every maneuver at `dt`: passed, run, failures."""
    env = dict(os.environ, **{DT_ENV: repr(dt)})
    proc = subprocess.run(["cargo", "test", "--release", "--no-fail-fast", "--test", "steady_state",
                           "--test", "braking"], cwd=ROOT, env=env, capture_output=True, text=True)
    out = proc.stdout + proc.stderr
    results = re.findall(r"test result: \w+\. (\d+) passed; (\d+) failed", out)
    if len(results) != 2:
        raise SystemExit(f"the validation tests did not run at dt = {dt}:\n{out[-3000:]}")
    passed = sum(int(p) for p, _ in results)
    failed = sum(int(f) for _, f in results)
    failures = []
    # "thread 'NAME' (id) panicked at FILE:\nMESSAGE": the test's name and its message's first line.
    for name, message in re.findall(r"thread '([^']+)'[^\n]* panicked at [^\n]*\n([^\n]*)", out):
        failures.append({"test": name, "message": message.strip()})
    return {"passed": passed, "run": passed + failed, "failures": failures}


def closed_loop(binary: str, scenario: str, sweep_runs: int, tmp: str, tag: str) -> dict:
    """The platoon's nominal run and `sweep_runs` randomised instances: runs, completed,
    contacts, fallback plans."""
    run_json = os.path.join(tmp, f"run_{tag}.json")
    sweep_json = os.path.join(tmp, f"sweep_{tag}.json")
    for cmd in ([binary, "run", "--scenario", scenario, "--no-rrd", "--json", run_json, "--quiet"],
                [binary, "sweep", "--scenario", scenario, "--runs", str(sweep_runs), "--seed", "42",
                 "--json", sweep_json, "--quiet"]):
        proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if proc.returncode != 0:
            raise SystemExit(f"merge_sim failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr}")
    with open(run_json, encoding="utf-8") as f:
        run = json.load(f)
    with open(sweep_json, encoding="utf-8") as f:
        sweep = json.load(f)
    samples = sweep["samples"]
    completed = [s for s in samples if s.get("status") == "completed"]
    return {
        "runs": 1 + len(samples),
        "completed": 1 + len(completed),
        "contacts": int(run["collisions"]) + sum(int(s["collisions"]) for s in completed),
        "fallbacks": int((run.get("planner_stats") or {}).get("fallbacks", 0))
        + sum(int(s.get("fallbacks", 0)) for s in completed),
        "min_gap_m": min([run["min_gap_m"]] + [s["min_gap_m"] for s in completed if s.get("min_gap_m") is not None]),
    }


def coarsest_valid_step(rows: list[dict]) -> float | None:
    """The largest step that is valid with every finer candidate valid too (a step that passes
    while a finer one fails is not taken), or None."""
    best = None
    for r in sorted(rows, key=lambda r: r["dt_s"]):
        if not r["valid"]:
            break
        best = r["dt_s"]
    return best


def main() -> int:
    args = parse_args()
    info = provenance(ROOT, args.bin, {})
    tmp = tempfile.mkdtemp(prefix="mergesim-dt-validity-")
    generated = subprocess.run([args.bin, "scenario", "platoon", "--vehicles", str(args.vehicles)],
                               capture_output=True, text=True)
    if generated.returncode != 0:
        raise SystemExit(f"merge_sim scenario platoon failed: {generated.stderr}")
    rows = []
    for dt in args.steps:
        log(f"dt = {dt} s: validation tests ...")
        tests = validation_tests(dt)
        scenario = os.path.join(tmp, f"platoon_{dt!r}.toml")
        with open(scenario, "w", encoding="utf-8") as f:
            f.write(with_physics_step(generated.stdout, dt))
        log(f"dt = {dt} s: closed loop (nominal platoon + {args.sweep_runs} instances) ...")
        loop = closed_loop(args.bin, scenario, args.sweep_runs, tmp, repr(dt))
        valid = (tests["passed"] == tests["run"] and loop["completed"] == loop["runs"]
                 and loop["contacts"] == 0 and loop["fallbacks"] == 0)
        rows.append({"dt_s": dt, "tests": tests, "closed_loop": loop, "valid": valid})

    out = ["### Physics steps at which the Rapier vehicle is valid", ""]
    out.append(f"- date: {info['date']}; machine: {info['machine']}, {info['cpu_model']}")
    out.append(f"- mergesim checkout {info['mergesim_commit'][:12]}"
               f"{' (dirty tree)' if info['mergesim_tree_dirty'] else ''}; binary {args.bin} "
               f"({info['merge_sim_version']}, built {info['merge_sim_binary_mtime']})")
    out.append(f"- validation tests: `{DT_ENV}=dt cargo test --release --test steady_state --test braking`; "
               f"closed loop: `merge_sim scenario platoon --vehicles {args.vehicles}` at dt, nominal `run` "
               f"and `sweep --runs {args.sweep_runs} --seed 42`")
    out.append("")
    out.append("| dt (s) | physics rate (Hz) | validation tests passed | closed-loop runs completed | contacts "
               "| fallback plans | closest gap (m) | valid | what fails |")
    out.append("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |")
    for r in rows:
        t, c = r["tests"], r["closed_loop"]
        fails = "; ".join(f"`{f['test']}`: {f['message']}" for f in t["failures"]) or "—"
        out.append(f"| {r['dt_s']:g} | {1.0 / r['dt_s']:g} | {t['passed']} / {t['run']} | "
                   f"{c['completed']} / {c['runs']} | {c['contacts']} | {c['fallbacks']} | "
                   f"{c['min_gap_m']:.2f} | {'yes' if r['valid'] else 'no'} | {fails} |")
    coarsest = coarsest_valid_step(rows)
    out.append("")
    out.append(f"Coarsest valid step (it and every finer candidate valid): {coarsest:g} s "
               f"({1.0 / coarsest:g} Hz)." if coarsest is not None
               else "No candidate step is valid together with every finer candidate.")
    print("\n".join(out))
    if args.json_path:
        with open(args.json_path, "w", encoding="utf-8") as f:
            json.dump({"environment": info, "rows": rows}, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
