#!/usr/bin/env python3
"""How far the closed loop moves when only a solver tolerance changes (README.md beside this
file), from the report that `merge_sim study tolerance_floor.toml` writes beside the plan.

Fixed with the plan, before any of its runs. Per parameter set, planner and figure (pre-contact),
over the instances both cells completed, three paired differences:
  F  = Clarabel at 1e-8 − Clarabel at 1e-7           (the floor: Clarabel against itself)
  B  = banded at 1e-7 − Clarabel at 1e-7              (solver_equivalence's comparison, again)
  B8 = banded at 1e-8 − Clarabel at 1e-8              (the same at the tighter tolerance)
each with its mean, 95 % t-interval, n, standard deviation, bit-identical pairs and whether the
CI lies inside ±delta/10 (the banded solver's criterion, docs/parameters.md); then the ratio
SD(F) / SD(B), the runs with a contact per cell with McNemar's exact test for F, the decision
on the hypothesis (README.md) and the replication check against solver_equivalence's rows.

Usage: python3 docs/studies/solver_tolerance_floor/analyse.py [FOLDER]   (default: this folder)
"""

import json
import math
import statistics
import sys
from pathlib import Path

PLAN = "tolerance_floor"
FIGURES = [
    ("obstacle.max_abs_yaw_rate_radps", 0.01),
    ("ego.max_abs_yaw_rate_radps", 0.01),
    ("obstacle.min_speed_mps", 0.5),
    ("min_gap_m", 0.5),
]
# The three paper-set figures whose banded − Clarabel CI reached beyond ±delta/10 in
# docs/studies/solver_equivalence (RESULTS.md): the hypothesis is decided on these.
DECIDING = [
    ("pf-sp", "ego.max_abs_yaw_rate_radps"),
    ("pf-iso", "obstacle.max_abs_yaw_rate_radps"),
    ("pf-iso", "ego.max_abs_yaw_rate_radps"),
]
COMPARISONS = [
    ("F", ("clarabel", "1e-8"), ("clarabel", "1e-7")),
    ("B", ("banded", "1e-7"), ("clarabel", "1e-7")),
    ("B8", ("banded", "1e-8"), ("clarabel", "1e-8")),
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


def cell_key(label):
    s = "paper" if 'params="paper"' in label else "mergesim"
    prog = "banded" if "newton-qp-banded" in label else "clarabel"
    if "solver_tolerance=0.0000001," in label or label.endswith("solver_tolerance=0.0000001"):
        tol = "1e-7"
    elif "solver_tolerance=0.00000001" in label:
        tol = "1e-8"
    else:
        raise SystemExit(f"error: cell {label!r}: no solver_tolerance level of the plan")
    return s, prog, tol


def paired(runs, s, planner, figure, a_key, b_key, instances):
    """Differences a − b of `figure` over the instances both completed, and the identical pairs."""
    d, same = [], 0
    for i in range(instances):
        a = runs.get((s, planner) + a_key + (i,))
        b = runs.get((s, planner) + b_key + (i,))
        if a is None or b is None:
            continue
        va = a["endpoints"][figure]["pre_contact"]
        vb = b["endpoints"][figure]["pre_contact"]
        if va is None or vb is None or not all(map(math.isfinite, (va, vb))):
            continue
        d.append(va - vb)
        same += va == vb
    return d, same


def main():
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    rep = folder / f"{PLAN}.report"
    if not (rep / "report.json").is_file():
        print(f"error: {rep / 'report.json'}: missing (run `merge_sim study {folder / PLAN}.toml`)",
              file=sys.stderr)
        sys.exit(2)
    report = json.loads((rep / "report.json").read_text())
    rows = [json.loads(l) for l in (rep / "rows.jsonl").read_text().splitlines() if l]
    cell = {i: cell_key(label) for i, label in enumerate(report["cells"])}
    n_inst = report["instances"]
    runs = {}
    for r in rows:
        if r["status"] != "completed":
            continue
        s, prog, tol = cell[r["cell"]]
        runs[(s, r["planner"], prog, tol, r["instance"])] = r

    sd = {}
    clarabel_passes = True
    print("## Paired differences (pre-contact)\n")
    print("F = Clarabel 1e-8 − Clarabel 1e-7 (the floor); B = banded − Clarabel at 1e-7; "
          "B8 = banded − Clarabel at 1e-8.\n")
    print("| set | planner | figure | comparison | mean difference, 95 % CI, n | SD | identical pairs | inside ±δ/10 |")
    print("|---|---|---|---|---|---|---|---|")
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            for figure, delta in FIGURES:
                for name, a_key, b_key in COMPARISONS:
                    d, same = paired(runs, s, planner, figure, a_key, b_key, n_inst)
                    if len(d) < 2:
                        print(f"| {s} | {planner} | {figure} | {name} | – ({len(d)}) | – | {same} | – |")
                        sd[(s, planner, figure, name)] = None
                        if name == "F":
                            clarabel_passes = False
                        continue
                    m = statistics.fmean(d)
                    sdev = statistics.stdev(d)
                    h = t975(len(d) - 1) * sdev / math.sqrt(len(d))
                    inside = -delta / 10 < m - h and m + h < delta / 10
                    if name == "F":
                        clarabel_passes &= inside
                    sd[(s, planner, figure, name)] = sdev
                    print(f"| {s} | {planner} | {figure} | {name} | {fmt(m)} [{fmt(m - h)}, "
                          f"{fmt(m + h)}], {len(d)} | {fmt(sdev)} | {same} | "
                          f"{'yes' if inside else '**no**'} |")

    print("\n## SD(F) / SD(B): the floor against the banded solver's spread\n")
    print("| set | planner | figure | SD(F) | SD(B) | SD(F) / SD(B) |")
    print("|---|---|---|---|---|---|")
    ratios = {}
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            for figure, _ in FIGURES:
                f = sd.get((s, planner, figure, "F"))
                b = sd.get((s, planner, figure, "B"))
                r = f / b if f is not None and b else None
                ratios[(s, planner, figure)] = r
                print(f"| {s} | {planner} | {figure} | {fmt(f)} | {fmt(b)} | {fmt(r)} |")

    print("\n## Runs with a contact\n")
    print("| set | planner | Clarabel 1e-7 | Clarabel 1e-8 | banded 1e-7 | banded 1e-8 | F: only 1e-7 | F: only 1e-8 | F: McNemar p |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            counts = {}
            for key in (("clarabel", "1e-7"), ("clarabel", "1e-8"), ("banded", "1e-7"), ("banded", "1e-8")):
                counts[key] = sum(runs[k]["collided"] for k in runs if k[:4] == (s, planner) + key)
            only_a = only_b = 0
            for i in range(n_inst):
                a = runs.get((s, planner, "clarabel", "1e-7", i))
                b = runs.get((s, planner, "clarabel", "1e-8", i))
                if a is None or b is None:
                    continue
                only_a += a["collided"] and not b["collided"]
                only_b += b["collided"] and not a["collided"]
            p = mcnemar_exact(only_a, only_b)
            clarabel_passes &= p >= 0.05
            c = [counts[k] for k in (("clarabel", "1e-7"), ("clarabel", "1e-8"), ("banded", "1e-7"), ("banded", "1e-8"))]
            print(f"| {s} | {planner} | {c[0]} | {c[1]} | {c[2]} | {c[3]} | {only_a} | {only_b} | {p:.3g} |")
    failed = sum(1 for r in rows if r["status"] != "completed")
    print(f"\nRuns that did not complete: {failed}.\n")

    # Replication: the 1e-7 cells are solver_equivalence's cells on later code.
    eq = folder.parent / "solver_equivalence" / "banded_vs_clarabel.report"
    if (eq / "rows.jsonl").is_file():
        eq_report = json.loads((eq / "report.json").read_text())
        eq_cell = {}
        for i, label in enumerate(eq_report["cells"]):
            eq_cell[i] = ("paper" if 'params="paper"' in label else "mergesim",
                          "banded" if "newton-qp-banded" in label else "clarabel")
        same = total = 0
        for line in (eq / "rows.jsonl").read_text().splitlines():
            if not line:
                continue
            r = json.loads(line)
            if r["status"] != "completed":
                continue
            s, prog = eq_cell[r["cell"]]
            ours = runs.get((s, r["planner"], prog, "1e-7", r["instance"]))
            if ours is None:
                continue
            total += 1
            same += all(ours["endpoints"][f]["pre_contact"] == r["endpoints"][f]["pre_contact"]
                        for f, _ in FIGURES) and ours["collided"] == r["collided"]
        print("## Replication of solver_equivalence\n")
        print(f"Runs of the 1e-7 cells with every figure and the contact identical to "
              f"solver_equivalence's (same instances, cells and planners): {same} of {total}.\n")

    print("## Decision\n")
    rs = [ratios.get(("paper", p, f)) for p, f in DECIDING]
    desc = ", ".join(f"{p} {f} {fmt(r)}" for (p, f), r in zip(DECIDING, rs))
    if any(r is None for r in rs):
        verdict = "inconclusive (a ratio is undefined)"
    elif all(r >= 1 / 3 for r in rs):
        verdict = "supported"
    elif all(r < 1 / 10 for r in rs):
        verdict = "refuted"
    else:
        verdict = "inconclusive"
    print(f"SD(F) / SD(B) on the deciding figures of the paper set: {desc}.\n")
    print(f"The hypothesis (README.md) is **{verdict}**.\n")
    print("Clarabel against itself (F) " + ("passes" if clarabel_passes else "**does not pass**")
          + " the banded solver's criterion (every CI inside ±δ/10, every McNemar p ≥ 0.05).")


if __name__ == "__main__":
    main()
