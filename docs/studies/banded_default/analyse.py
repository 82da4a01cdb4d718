#!/usr/bin/env python3
"""Could the banded solver be the default? (README.md beside this file), from the report that
`merge_sim study banded_default.toml` writes beside the plan.

Fixed with the plan, before any of its runs. Per parameter set, planner and figure (pre-contact),
over the instances both cells completed:
  F  = Clarabel at 1e-8 − Clarabel at 1e-7     (the floor: Clarabel against itself)
  B  = banded at 1e-7 − Clarabel at 1e-7       (the change that would be made)
  B8 = banded at 1e-8 − Clarabel at 1e-8       (reported, deciding nothing)
each with its mean, 95 % t-interval, n, standard deviation (SD) and bit-identical pairs. The
criterion (README.md), for PF-SP and PF-ISO in both sets, on every figure:
  (a) B's 95 % CI inside ±delta/10, or
  (b) SD(B) <= 2 SD(F), with SD(F) > 0, and B's 95 % CI inside ±delta/2;
on the runs with a contact: McNemar's exact test of B (banded against Clarabel at 1e-7) with
p >= 0.05; and every run of the two 1e-7 cells completed. Admitted if all hold.

Usage: python3 docs/studies/banded_default/analyse.py [FOLDER]   (default: this folder)
"""

import json
import math
import statistics
import sys
from pathlib import Path

PLAN = "banded_default"
FIGURES = [
    ("obstacle.max_abs_yaw_rate_radps", 0.01),
    ("ego.max_abs_yaw_rate_radps", 0.01),
    ("obstacle.min_speed_mps", 0.5),
    ("min_gap_m", 0.5),
]
# The planners the banded solver changes (PF-CS optimises no speeds).
DECIDING_PLANNERS = ["pf-sp", "pf-iso"]
SD_FACTOR = 2.0
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


def summary(d):
    """Mean, CI half-width and SD of the differences d (None if fewer than two)."""
    if len(d) < 2:
        return None
    m = statistics.fmean(d)
    sdev = statistics.stdev(d)
    return m, t975(len(d) - 1) * sdev / math.sqrt(len(d)), sdev


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

    failures = []
    print("## Paired differences (pre-contact)\n")
    print("F = Clarabel 1e-8 − Clarabel 1e-7 (the floor); B = banded − Clarabel at 1e-7 (the "
          "change); B8 = banded − Clarabel at 1e-8. δ: the figure's practical threshold.\n")
    print("| set | planner | figure | comparison | mean difference, 95 % CI, n | SD | identical pairs |")
    print("|---|---|---|---|---|---|---|")
    stats = {}
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            for figure, delta in FIGURES:
                for name, a_key, b_key in COMPARISONS:
                    d, same = paired(runs, s, planner, figure, a_key, b_key, n_inst)
                    st = summary(d)
                    stats[(s, planner, figure, name)] = st
                    if st is None:
                        print(f"| {s} | {planner} | {figure} | {name} | – ({len(d)}) | – | {same} |")
                        continue
                    m, h, sdev = st
                    print(f"| {s} | {planner} | {figure} | {name} | {fmt(m)} [{fmt(m - h)}, "
                          f"{fmt(m + h)}], {len(d)} | {fmt(sdev)} | {same} |")

    print("\n## The criterion, figure by figure (PF-SP and PF-ISO)\n")
    print(f"(a) B's CI inside ±δ/10; (b) SD(B) ≤ {SD_FACTOR:g}·SD(F), SD(F) > 0, and B's CI inside ±δ/2.\n")
    print("| set | planner | figure | δ | B: 95 % CI | SD(B) / SD(F) | (a) | (b) | passes |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in ("paper", "mergesim"):
        for planner in DECIDING_PLANNERS:
            for figure, delta in FIGURES:
                b = stats.get((s, planner, figure, "B"))
                f = stats.get((s, planner, figure, "F"))
                if b is None:
                    failures.append(f"{s} {planner} {figure}: fewer than two pairs")
                    print(f"| {s} | {planner} | {figure} | {delta:g} | – | – | no | no | **no** |")
                    continue
                m, h, sd_b = b
                sd_f = f[2] if f is not None else None
                a_ok = -delta / 10 < m - h and m + h < delta / 10
                ratio = sd_b / sd_f if sd_f else None
                b_ok = (ratio is not None and sd_b <= SD_FACTOR * sd_f
                        and -delta / 2 < m - h and m + h < delta / 2)
                ok = a_ok or b_ok
                if not ok:
                    failures.append(f"{s} {planner} {figure}")
                print(f"| {s} | {planner} | {figure} | {delta:g} | [{fmt(m - h)}, {fmt(m + h)}] | "
                      f"{fmt(ratio)} | {'yes' if a_ok else 'no'} | {'yes' if b_ok else 'no'} | "
                      f"{'yes' if ok else '**no**'} |")

    print("\n## Runs with a contact\n")
    print("| set | planner | Clarabel 1e-7 | Clarabel 1e-8 | banded 1e-7 | banded 1e-8 | B: only Clarabel | B: only banded | B: McNemar p | F: only 1e-7 | F: only 1e-8 | F: McNemar p |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    keys = (("clarabel", "1e-7"), ("clarabel", "1e-8"), ("banded", "1e-7"), ("banded", "1e-8"))
    for s in ("paper", "mergesim"):
        for planner in report["planners"]:
            counts = [sum(runs[k]["collided"] for k in runs if k[:4] == (s, planner) + key) for key in keys]
            disc = {}
            for name, a_key, b_key in (("B", ("clarabel", "1e-7"), ("banded", "1e-7")),
                                       ("F", ("clarabel", "1e-7"), ("clarabel", "1e-8"))):
                only_a = only_b = 0
                for i in range(n_inst):
                    a = runs.get((s, planner) + a_key + (i,))
                    b = runs.get((s, planner) + b_key + (i,))
                    if a is None or b is None:
                        continue
                    only_a += a["collided"] and not b["collided"]
                    only_b += b["collided"] and not a["collided"]
                disc[name] = (only_a, only_b, mcnemar_exact(only_a, only_b))
            if planner in DECIDING_PLANNERS and disc["B"][2] < 0.05:
                failures.append(f"{s} {planner} contacts (McNemar p = {disc['B'][2]:.3g})")
            print(f"| {s} | {planner} | " + " | ".join(str(c) for c in counts) + " | "
                  + " | ".join(f"{disc[n][0]} | {disc[n][1]} | {disc[n][2]:.3g}" for n in ("B", "F")) + " |")

    incomplete = 0
    for s in ("paper", "mergesim"):
        for planner in DECIDING_PLANNERS:
            for key in (("clarabel", "1e-7"), ("banded", "1e-7")):
                done = sum(1 for i in range(n_inst) if (s, planner) + key + (i,) in runs)
                incomplete += n_inst - done
    if incomplete:
        failures.append(f"{incomplete} runs of the 1e-7 cells did not complete")
    failed = sum(1 for r in rows if r["status"] != "completed")
    print(f"\nRuns that did not complete (all cells): {failed}.\n")

    print("## Decision\n")
    if failures:
        print("The banded solver is **not admitted** as the default. Failing: " + "; ".join(failures) + ".")
    else:
        print("The banded solver is **admitted** as the default: every figure of PF-SP and PF-ISO in "
              "both sets passes (a) or (b), no McNemar p < 0.05, every run of the 1e-7 cells completed.")


if __name__ == "__main__":
    main()
