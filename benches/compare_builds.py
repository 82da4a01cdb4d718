#!/usr/bin/env python3
"""Paired wall-clock comparison of two merge_sim builds on the same command.

Runs `OLD ARGS...` and `NEW ARGS...` in pairs, the order swapped from pair to pair (old then
new, new then old, ...) so that a position effect (warm caches, clock boost) does not favour
one build; the first pair is an untimed warm-up. Times each whole process and prints the median
of the per-pair ratios new / old with its range, beside each build's median wall time. Pairing keeps the ratio
meaningful when the machine's speed drifts during the comparison (it does: the same binary has
run 1.6x slower in an evening than in a morning on the development machine).

When the command writes a run JSON (`run ... --json PATH`) or a sweep JSON (`sweep ... --json
PATH`), give PATH as `{out}`: each build then writes its own file, and with --same-results the
two files are compared after every pair, wall-clock fields (`wall_time_s`, `wall_s`, `profile`,
the planner's `*_us` timings) left out, so a speed-up that should change no result is checked
to change none.

Usage:
  python3 benches/compare_builds.py --old OLD_BIN --new NEW_BIN [--reps N] [--same-results] \
      -- run --scenario urgent_merge --no-rrd --quiet --json {out}

Environment variables (RAYON_NUM_THREADS for one core) pass through to both builds.
Exit code 2 on bad usage, 1 if a run fails or --same-results finds a difference.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

WALL_CLOCK_KEYS = {"wall_time_s", "wall_s", "profile"}


def strip_wall_clock(value):
    """The JSON without the fields that measure wall-clock time."""
    if isinstance(value, dict):
        return {
            k: strip_wall_clock(v)
            for k, v in value.items()
            if k not in WALL_CLOCK_KEYS and not k.endswith("_us")
        }
    if isinstance(value, list):
        return [strip_wall_clock(v) for v in value]
    return value


def run_once(binary, args, out_path):
    cmd = [binary] + [a.replace("{out}", out_path) for a in args]
    start = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall_s = time.perf_counter() - start
    if done.returncode != 0:
        print(f"error: {' '.join(cmd)} exited {done.returncode}:\n{done.stderr}", file=sys.stderr)
        sys.exit(1)
    return wall_s


def main():
    parser = argparse.ArgumentParser(
        description="Paired wall-clock comparison of two merge_sim builds (module docstring).")
    parser.add_argument("--old", required=True, help="the baseline merge_sim binary")
    parser.add_argument("--new", required=True, help="the merge_sim binary under test")
    parser.add_argument("--reps", type=int, default=7, help="timed pairs (default 7)")
    parser.add_argument("--same-results", action="store_true",
                        help="compare the two builds' {out} JSONs after every pair")
    parser.add_argument("args", nargs=argparse.REMAINDER,
                        help="after --: the merge_sim arguments ({out}: each build's JSON path)")
    a = parser.parse_args()
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    if not args:
        parser.error("no merge_sim arguments after --")
    if a.reps < 1:
        parser.error("--reps must be at least 1")
    for b in (a.old, a.new):
        if not (os.path.isfile(b) and os.access(b, os.X_OK)):
            parser.error(f"{b}: not an executable file")
    if a.same_results and not any("{out}" in x for x in args):
        parser.error("--same-results needs {out} in the merge_sim arguments")
    with tempfile.TemporaryDirectory() as tmp:
        outs = {"old": os.path.join(tmp, "old.json"), "new": os.path.join(tmp, "new.json")}
        walls = {"old": [], "new": []}
        for rep in range(a.reps + 1):
            pair = {}
            order = [("old", a.old), ("new", a.new)]
            if rep % 2 == 0:
                order.reverse()
            for name, binary in order:
                if os.path.exists(outs[name]):
                    os.remove(outs[name])  # a run that writes nothing is not compared stale
                pair[name] = run_once(binary, args, outs[name])
            if a.same_results:
                for name in outs:
                    if not os.path.isfile(outs[name]):
                        print(f"error: pair {rep}: the {name} build wrote no {{out}} file",
                              file=sys.stderr)
                        sys.exit(1)
                with open(outs["old"]) as f_old, open(outs["new"]) as f_new:
                    if strip_wall_clock(json.load(f_old)) != strip_wall_clock(json.load(f_new)):
                        print(f"error: pair {rep}: the two builds' results differ", file=sys.stderr)
                        sys.exit(1)
            if rep == 0:
                continue  # warm-up
            for name in pair:
                walls[name].append(pair[name])
            print(f"pair {rep}/{a.reps}: old {pair['old']:.3f} s, new {pair['new']:.3f} s",
                  file=sys.stderr)
    ratios = [n / o for n, o in zip(walls["new"], walls["old"])]
    print(f"command: merge_sim {' '.join(args)}")
    print(f"old: {a.old}: median {statistics.median(walls['old']):.3f} s "
          f"({min(walls['old']):.3f}-{max(walls['old']):.3f})")
    print(f"new: {a.new}: median {statistics.median(walls['new']):.3f} s "
          f"({min(walls['new']):.3f}-{max(walls['new']):.3f})")
    print(f"new / old wall, median of {a.reps} pairs: {statistics.median(ratios):.4f} "
          f"({min(ratios):.4f}-{max(ratios):.4f})")
    if a.same_results:
        print("results: identical in every pair (wall-clock fields aside)")


if __name__ == "__main__":
    main()
