#!/usr/bin/env python3
"""Compare two `merge_sim grid --csv` files of the same instances, run by two builds.

Usage: scripts/compare_grid_runs.py BEFORE.csv AFTER.csv [--reference pf-cs]

For every vehicle, figure and planner it prints:
- how many instances give bit-identical values in both files;
- the paired difference against the reference planner (mean ± standard error, as `grid`
  prints it) before and after;
- the move of that mean, in units of the 95 % confidence half-width (1.96 standard errors)
  of the difference before. A move above 1 is flagged `MOVED`.
It then prints the runs with a collision and the collision episodes per planner, before and
after. Only the Python standard library is used.
"""
import argparse
import csv
import math
import sys
from collections import defaultdict

FIGURES = [
    "peak_yaw_rate_radps",
    "merge_zone_rms_yaw_rate_radps",
    "outside_merge_zone_rms_yaw_rate_radps",
    "peak_sideslip_rad",
    "min_speed_mps",
    "slowing_onset_s",
    "path_length_m",
]


def read(path):
    """(planner, instance, vehicle) -> row."""
    rows = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            rows[(row["planner"], int(row["instance"]), row["vehicle"])] = row
    return rows


def value(row, figure):
    text = row.get(figure, "")
    if text == "" or row.get("error"):
        return None
    return float(text)


def mean_se(values):
    n = len(values)
    if n == 0:
        return float("nan"), float("nan"), 0
    m = sum(values) / n
    if n < 2:
        return m, float("nan"), n
    var = sum((v - m) ** 2 for v in values) / (n - 1)
    return m, math.sqrt(var / n), n


def paired(rows, planner, reference, vehicle, figure, instances):
    diffs = []
    for i in instances:
        a = rows.get((planner, i, vehicle))
        b = rows.get((reference, i, vehicle))
        if a is None or b is None:
            continue
        va, vb = value(a, figure), value(b, figure)
        if va is None or vb is None:
            continue
        diffs.append(va - vb)
    return mean_se(diffs)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--reference", default="pf-cs")
    args = ap.parse_args()
    before, after = read(args.before), read(args.after)
    if set(before) != set(after):
        sys.exit("the two files do not hold the same planners, instances and vehicles")
    planners = sorted({k[0] for k in before}, key=lambda p: (p != args.reference, p))
    vehicles = sorted({k[2] for k in before})
    instances = sorted({k[1] for k in before})
    moved = 0
    compared = 0
    print(f"{'vehicle':<10} {'figure':<40} {'planner':<12} {'identical':>9}  "
          f"{'diff before':>22}  {'diff after':>22}  {'move/CI95':>9}")
    for vehicle in vehicles:
        for figure in FIGURES:
            for planner in planners:
                same = sum(
                    1
                    for i in instances
                    if before[(planner, i, vehicle)].get(figure) == after[(planner, i, vehicle)].get(figure)
                )
                line = f"{vehicle:<10} {figure:<40} {planner:<12} {same:>5}/{len(instances):<3}"
                if planner == args.reference:
                    print(line)
                    continue
                mb, sb, nb = paired(before, planner, args.reference, vehicle, figure, instances)
                ma, sa, na = paired(after, planner, args.reference, vehicle, figure, instances)
                half = 1.96 * sb
                if nb == 0 or na == 0:
                    print(line + "  no pairs")
                    continue
                move = abs(ma - mb) / half if half > 0 else (0.0 if ma == mb else math.inf)
                compared += 1
                flag = ""
                if move > 1.0:
                    moved += 1
                    flag = "  MOVED"
                print(f"{line}  {mb:>12.6g} ± {sb:<8.2g}  {ma:>12.6g} ± {sa:<8.2g}  {move:>9.2f}{flag}"
                      + ("" if na == nb else f"  (n {nb} -> {na})"))
    print(f"\n{moved} of {compared} paired differences moved by more than their 95 % CI half-width")
    print("\nruns with a collision (collision episodes), before -> after")
    for planner in planners:
        def tally(rows):
            runs, episodes = 0, 0
            for i in instances:
                per_run = [rows[(planner, i, v)] for v in vehicles]
                c = int(per_run[0]["collisions"] or 0)
                runs += c > 0
                episodes += c
            return runs, episodes
        rb, eb = tally(before)
        ra, ea = tally(after)
        print(f"{planner:<12} {rb:>4} ({eb}) -> {ra:>4} ({ea})")


if __name__ == "__main__":
    main()
