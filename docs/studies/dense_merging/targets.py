#!/usr/bin/env python3
"""The dense-merging targets (README.md beside this file), decided from the study reports.

Usage: python3 targets.py FOLDER [--markdown]

For every plan ``FOLDER/<plan>.toml`` whose report ``FOLDER/<plan>.report/`` exists, per planner:
runs, runs with a collision (k / n, exact Clopper-Pearson 95 % upper bound), runs with an
unmerged car and the mean per run, mean throughput; for ``pf-iso-seq`` (the recommended
configuration) each target met or not, the throughput target from the primary endpoint's
paired 95 % CI in ``report.json``. Standard library only. A plan without a report is listed as
not run; a report with failed runs is flagged (they count against nothing, and are listed).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

RECOMMENDED = "pf-iso-seq"
REFERENCE = "idm-mobil"
THROUGHPUT_DELTA_VPH = 100.0


def binomial_cdf(k: int, n: int, p: float) -> float:
    """P(X <= k) for X ~ Binomial(n, p)."""
    return sum(math.comb(n, i) * p**i * (1.0 - p) ** (n - i) for i in range(k + 1))


def clopper_pearson_upper(k: int, n: int, alpha: float = 0.05) -> float:
    """The exact two-sided (1 - alpha) upper bound on a proportion with k of n."""
    if n == 0:
        return float("nan")
    if k >= n:
        return 1.0
    lo, hi = k / n, 1.0
    for _ in range(200):  # bisection: P(X <= k | p) = alpha / 2
        mid = 0.5 * (lo + hi)
        if binomial_cdf(k, n, mid) > alpha / 2:
            lo = mid
        else:
            hi = mid
    return hi


def whole_run(row: dict, figure: str) -> float | None:
    value = row.get("endpoints", {}).get(figure, {}).get("whole_run")
    return None if value is None else float(value)


def plan_figures(report: Path) -> dict:
    rows = [json.loads(line) for line in (report / "rows.jsonl").read_text().splitlines() if line]
    analysis = json.loads((report / "report.json").read_text())["analysis"]
    out: dict = {}
    for planner in sorted({r["planner"] for r in rows}):
        mine = [r for r in rows if r["planner"] == planner]
        done = [r for r in mine if r["status"] == "completed"]
        collided = sum(1 for r in done if r["collided"])
        unmerged = [whole_run(r, "unmerged_vehicles") for r in done]
        unmerged = [u for u in unmerged if u is not None]
        throughput = [whole_run(r, "throughput_vph") for r in done]
        throughput = [t for t in throughput if t is not None and math.isfinite(t)]
        out[planner] = {
            "runs": len(mine),
            "failed": len(mine) - len(done),
            "collided": collided,
            "collided_upper95": clopper_pearson_upper(collided, len(done)),
            "runs_with_unmerged": sum(1 for u in unmerged if u > 0),
            "mean_unmerged": sum(unmerged) / len(unmerged) if unmerged else float("nan"),
            "mean_throughput_vph": sum(throughput) / len(throughput) if throughput else float("nan"),
        }
    for effect in analysis["endpoints"]:
        if effect["endpoint"] == "throughput_vph" and effect["planner"] in out:
            out[effect["planner"]]["throughput_diff"] = {
                "mean": effect["mean_difference"],
                "ci95": effect["ci95"],
                "n": effect["n"],
                "excluded": effect["n_excluded"],
            }
    return out


def targets(figures: dict) -> dict:
    seq = figures.get(RECOMMENDED)
    if seq is None:
        return {}
    diff = seq.get("throughput_diff")
    lower = None if diff is None or diff["ci95"] is None else diff["ci95"][0]
    upper = None if diff is None or diff["ci95"] is None else diff["ci95"][1]
    return {
        "no_collision": seq["collided"] == 0 and seq["failed"] == 0,
        "all_merged": seq["runs_with_unmerged"] == 0 and seq["failed"] == 0,
        "throughput_not_lower": lower is not None and lower > -THROUGHPUT_DELTA_VPH,
        "throughput_higher": lower is not None and lower > 0.0,
        "throughput_ci95": [lower, upper],
    }


def fmt(x: float | None, digits: int = 1) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}f}"


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    folder = Path(argv[1])
    plans = sorted(folder.glob("*.toml"))
    if not plans:
        print(f"error: no plan (*.toml) in {folder}", file=sys.stderr)
        return 2
    print("| plan | planner | runs (failed) | with a collision | 95 % upper bound | "
          "runs with an unmerged car | unmerged per run | throughput (veh/h) | "
          "Δ throughput vs idm-mobil [95 % CI] (n, excl.) |")
    print("|---|---|---|---|---|---|---|---|---|")
    decided = []
    for plan in plans:
        report = plan.with_suffix(".report")
        if not (report / "report.json").exists():
            print(f"| {plan.stem} | not run | | | | | | | |")
            continue
        figures = plan_figures(report)
        for planner, f in figures.items():
            d = f.get("throughput_diff")
            diff = "–" if d is None else (
                f"{fmt(d['mean'])} [{fmt(d['ci95'][0])}, {fmt(d['ci95'][1])}] "
                f"({d['n']}, {d['excluded']})")
            print(f"| {plan.stem} | {planner} | {f['runs']} ({f['failed']}) | {f['collided']} | "
                  f"{100 * f['collided_upper95']:.1f} % | {f['runs_with_unmerged']} | "
                  f"{fmt(f['mean_unmerged'], 2)} | {fmt(f['mean_throughput_vph'], 0)} | {diff} |")
        decided.append((plan.stem, targets(figures)))
    print()
    print(f"Targets for {RECOMMENDED}:")
    print()
    print("| plan | 1. no collision | 2. all merged | 3. throughput ≥ idm-mobil − 100 veh/h | higher |")
    print("|---|---|---|---|---|")
    for stem, t in decided:
        if not t:
            print(f"| {stem} | – | – | – | – |")
            continue
        yes = lambda b: "met" if b else "**not met**"  # noqa: E731
        print(f"| {stem} | {yes(t['no_collision'])} | {yes(t['all_merged'])} | "
              f"{yes(t['throughput_not_lower'])} | {'yes' if t['throughput_higher'] else 'no'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
