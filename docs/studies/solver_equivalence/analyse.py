#!/usr/bin/env python3
"""The closed-loop part of the banded solver's acceptance criterion (docs/parameters.md, "A
banded solver for the Newton QP: the criterion first"), from the report that `merge_sim study
banded_vs_clarabel.toml` writes beside the plan.

Fixed with the plan, before any of its runs. Per parameter set and planner, over the instances
both programs completed: for each figure (pre-contact) the paired difference banded − Clarabel
(mean, 95 % t-interval, n, bit-identical pairs) and whether its CI lies inside ±delta/10; the
runs with a contact under each program, the discordant pairs and the exact McNemar p. The
program is "equivalent" when every CI lies inside ±delta/10 and no McNemar p is below 0.05.

Usage: python3 docs/studies/solver_equivalence/analyse.py [FOLDER]   (default: this folder)
"""

import json
import math
import statistics
import sys
from pathlib import Path

PLAN = "banded_vs_clarabel"
FIGURES = [
    ("obstacle.max_abs_yaw_rate_radps", 0.01),
    ("ego.max_abs_yaw_rate_radps", 0.01),
    ("obstacle.min_speed_mps", 0.5),
    ("min_gap_m", 0.5),
]
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
        2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
        2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    if df <= 30:
        return T975[df - 1]
    z = 1.959964
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


def mcnemar_exact(b, c):
    n = b + c
    if n == 0:
        return 1.0
    k = min(b, c)
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2**n
    return min(1.0, 2 * tail)


def fmt(x, digits=3):
    return "–" if x is None else f"{x:.{digits}g}"


def main():
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    rep = folder / f"{PLAN}.report"
    if not (rep / "report.json").is_file():
        print(f"error: {rep / 'report.json'}: missing (run `merge_sim study {folder / PLAN}.toml`)",
              file=sys.stderr)
        sys.exit(2)
    report = json.loads((rep / "report.json").read_text())
    rows = [json.loads(l) for l in (rep / "rows.jsonl").read_text().splitlines() if l]
    cell = {}
    for i, label in enumerate(report["cells"]):
        s = "paper" if 'params="paper"' in label else "mergesim"
        prog = "banded" if "newton-qp-banded" in label else "clarabel"
        cell[i] = (s, prog)
    runs = {}
    for r in rows:
        if r["status"] != "completed":
            continue
        s, prog = cell[r["cell"]]
        runs[(s, r["planner"], prog, r["instance"])] = r
    equivalent = True
    print("## Banded − Clarabel, paired over the same instances (pre-contact)\n")
    print("| set | planner | figure | mean difference, 95 % CI, n | identical pairs | inside ±δ/10 |")
    print("|---|---|---|---|---|---|")
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            for figure, delta in FIGURES:
                d, same = [], 0
                for i in range(report["instances"]):
                    a = runs.get((s, planner, "clarabel", i))
                    b = runs.get((s, planner, "banded", i))
                    if a is None or b is None:
                        continue
                    va = a["endpoints"][figure]["pre_contact"]
                    vb = b["endpoints"][figure]["pre_contact"]
                    if va is None or vb is None or not all(map(math.isfinite, (va, vb))):
                        continue
                    d.append(vb - va)
                    same += va == vb
                if len(d) < 2:
                    print(f"| {s} | {planner} | {figure} | – ({len(d)}) | {same} | – |")
                    continue
                m = statistics.fmean(d)
                h = t975(len(d) - 1) * statistics.stdev(d) / math.sqrt(len(d))
                inside = -delta / 10 < m - h and m + h < delta / 10
                equivalent &= inside
                print(f"| {s} | {planner} | {figure} | {fmt(m)} [{fmt(m - h)}, {fmt(m + h)}], "
                      f"{len(d)} | {same} | {'yes' if inside else '**no**'} |")
    print("\n## Runs with a contact\n")
    print("| set | planner | Clarabel | banded | only Clarabel | only banded | McNemar p |")
    print("|---|---|---|---|---|---|---|")
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            ca = cb = only_a = only_b = 0
            for i in range(report["instances"]):
                a = runs.get((s, planner, "clarabel", i))
                b = runs.get((s, planner, "banded", i))
                if a is None or b is None:
                    continue
                ca += a["collided"]
                cb += b["collided"]
                only_a += a["collided"] and not b["collided"]
                only_b += b["collided"] and not a["collided"]
            p = mcnemar_exact(only_a, only_b)
            equivalent &= p >= 0.05
            print(f"| {s} | {planner} | {ca} | {cb} | {only_a} | {only_b} | {p:.3g} |")
    failed = sum(1 for r in rows if r["status"] != "completed")
    print(f"\nRuns that did not complete: {failed}.\n")
    print("## Decision\n")
    print("The banded program is **" + ("equivalent" if equivalent else "not shown equivalent")
          + "** to Clarabel's Newton QP at a tenth of the studies' thresholds.")


if __name__ == "__main__":
    main()
