#!/usr/bin/env python3
"""Summary tables of the magnitude study (README.md in this folder), from the report that
`merge_sim study cubic_bounds.toml` writes beside the plan (cubic_bounds.report/).

Fixed with the plan, before any of its runs. It only reads the report (report.json for the
cells, rows.jsonl for every run's endpoints) and prints Markdown on stdout:

1. how often the cubic met a bound: per parameter set, bounds (in use, relaxed x 4), planner
   and vehicle (obstacle, ego), over the completed runs: how many runs have at least one
   planning cycle whose cubic met a bound before the run's first contact, the mean share of
   such cycles (`path_fit_bound_share`, pre-contact) and the largest;
2. the relaxation: per parameter set and planner, the paired change of the obstacle's peak yaw
   rate (pre-contact) from the bounds in use to the bounds relaxed x 4, on the same instances
   (mean, 95 % t-interval, n, and how many instances give bit-identical peaks), and whether it
   rises by more than delta = 0.01 rad/s (its CI entirely above +delta);
3. the decision of the protocol (README.md, "Decision rule"): the cubic half of the magnitude
   explanation is "supported" only if, in the paper set, the peak rises by more than delta
   with PF-CS and with PF-ISO; else "not supported". The mergesim set's rows are descriptive.

Usage: python3 docs/studies/paper_magnitude/analyse.py [FOLDER]   (default: this folder)
Exits 2 naming the missing report when it is absent.
"""

import json
import math
import statistics
import sys
from pathlib import Path

PLAN = "cubic_bounds"
PRIMARY = "obstacle.max_abs_yaw_rate_radps"
SHARE = "{}.path_fit_bound_share"
CS, ISO = "pf-cs", "pf-iso"
DELTA = 0.01
IN_USE = "sim.planner.cubic_max_curvature_per_m=0.05"
RELAXED = "sim.planner.cubic_max_curvature_per_m=0.2"

# Two-sided 95 % t quantiles for 1..30 degrees of freedom (beyond: a Cornish-Fisher series).
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
        2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
        2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    if df <= 30:
        return T975[df - 1]
    z = 1.959964
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


def set_of(label):
    for s in ("paper", "mergesim"):
        if f'params="{s}"' in label:
            return s
    return "mergesim"


def bounds_of(label):
    plain = label.replace('"', "").replace(" ", "")
    if IN_USE in plain:
        return "in use"
    if RELAXED in plain:
        return "relaxed x 4"
    return None


def fmt(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


def load(folder):
    rep = folder / f"{PLAN}.report"
    path = rep / "report.json"
    if not path.is_file():
        print(f"error: {path}: missing (run `merge_sim study {folder / PLAN}.toml`)",
              file=sys.stderr)
        sys.exit(2)
    report = json.loads(path.read_text())
    rows = [json.loads(line) for line in (rep / "rows.jsonl").read_text().splitlines() if line]
    return report, rows


def cells_by(report):
    """{(set, bounds): cell index}."""
    out = {}
    for i, label in enumerate(report["cells"]):
        b = bounds_of(label)
        if b is not None:
            out[(set_of(label), b)] = i
    return out


def values(rows, cell, planner, endpoint):
    """{instance: pre-contact value} over the completed runs."""
    out = {}
    for r in rows:
        if r["cell"] == cell and r["planner"] == planner and r["status"] == "completed":
            v = r["endpoints"].get(endpoint, {}).get("pre_contact")
            if v is not None:
                out[r["instance"]] = v
    return out


def counts(report, rows):
    print("## How often the cubic met a bound (pre-contact)\n")
    print("| set | bounds | planner | vehicle | runs | runs with a bound met | mean share of "
          "cycles | largest share |")
    print("|---|---|---|---|---|---|---|---|")
    cells = cells_by(report)
    for s in ("paper", "mergesim"):
        for b in ("in use", "relaxed x 4"):
            for planner in (CS, ISO):
                for vehicle in ("obstacle", "ego"):
                    v = list(values(rows, cells[(s, b)], planner, SHARE.format(vehicle)).values())
                    if not v:
                        print(f"| {s} | {b} | {planner} | {vehicle} | 0 | – | – | – |")
                        continue
                    met = sum(1 for x in v if x > 0)
                    print(f"| {s} | {b} | {planner} | {vehicle} | {len(v)} | {met} | "
                          f"{fmt(statistics.fmean(v))} | {fmt(max(v))} |")
    print()


def relaxation(report, rows):
    print("## The obstacle's peak yaw rate, bounds relaxed x 4 − in use (pre-contact)\n")
    print("| set | planner | in use: mean (rad/s) | relaxed: mean (rad/s) | change, 95 % CI, n | "
          "identical peaks | rises by more than 0.01 rad/s |")
    print("|---|---|---|---|---|---|---|")
    cells = cells_by(report)
    rises = {}
    for s in ("paper", "mergesim"):
        for planner in (CS, ISO):
            a = values(rows, cells[(s, "in use")], planner, PRIMARY)
            b = values(rows, cells[(s, "relaxed x 4")], planner, PRIMARY)
            both = sorted(set(a) & set(b))
            d = [b[i] - a[i] for i in both]
            same = sum(1 for i in both if a[i] == b[i])
            if len(d) < 2:
                print(f"| {s} | {planner} | – | – | – ({len(d)} pairs) | {same} | no |")
                rises[(s, planner)] = False
                continue
            m = statistics.fmean(d)
            h = t975(len(d) - 1) * statistics.stdev(d) / math.sqrt(len(d))
            rise = m - h > DELTA
            rises[(s, planner)] = rise
            print(f"| {s} | {planner} | {fmt(statistics.fmean(a[i] for i in both))} | "
                  f"{fmt(statistics.fmean(b[i] for i in both))} | {fmt(m)} [{fmt(m - h)}, "
                  f"{fmt(m + h)}], {len(d)} | {same} | {'yes' if rise else 'no'} |")
    print()
    return rises


def main():
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    report, rows = load(folder)
    counts(report, rows)
    rises = relaxation(report, rows)
    supported = rises[("paper", CS)] and rises[("paper", ISO)]
    print("## Decision\n")
    print("The cubic half of the magnitude explanation (the bounds of Eq. 9 keep the `paper` "
          "set's peaks small): **" + ("supported" if supported else "not supported") + "**.")


if __name__ == "__main__":
    main()
