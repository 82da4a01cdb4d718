#!/usr/bin/env python3
"""The paper's claims, decided per parameter set from the report that `merge_sim study
comparison.toml` writes beside the plan (comparison.report/). Fixed with the plan, before any
of its runs (README.md in this folder: the claims and their decision rules).

Reads report.json (effects against PF-CS, collisions) and rows.jsonl (pairs between two
non-reference planners, slowing onsets) and prints Markdown on stdout.

Usage: python3 docs/studies/paper_comparison/analyse.py [REPORT_DIR]
   (default: comparison.report beside this script). Exits 2 when the report is missing.
"""

import json
import math
import statistics
import sys
from pathlib import Path

CS, SP, ISO, PRED, EQ10 = "pf-cs", "pf-sp", "pf-iso", "pf-iso-pred", "pf-sp-eq10"
PEAK = "obstacle.max_abs_yaw_rate_radps"
EGO_PEAK = "ego.max_abs_yaw_rate_radps"
MIN_SPEED = "obstacle.min_speed_mps"
ONSET = "obstacle.slowing_onset_s"
DELTA_R = 0.01  # rad/s, the plan's threshold of the yaw-rate endpoints

# Two-sided 97.5 % quantiles of Student's t, df 1..30; beyond, a Cornish-Fisher series.
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
        2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
        2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    if df <= 30:
        return T975[df - 1]
    z = 1.959964
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


def fmt(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


def verdict(mean, lo, hi, delta):
    if lo > -delta and hi < delta:
        return "negligible"
    if lo > delta:
        return "relevant +"
    if hi < -delta:
        return "relevant −"
    return "inconclusive"


def paired(rows, cell, a, b, endpoint):
    """Mean of a − b over the instances where both completed and both values (pre-contact)
    are finite, its 95 % t-interval and n; None below 2 pairs."""
    val = {}
    for r in rows:
        if r["cell"] == cell and r["status"] == "completed":
            v = r["endpoints"][endpoint]["pre_contact"]
            if v is not None and math.isfinite(v):
                val[(r["planner"], r["instance"])] = v
    d = [val[(a, i)] - val[(b, i)] for (p, i) in val if p == a and (b, i) in val]
    if len(d) < 2:
        return None
    m = statistics.fmean(d)
    h = t975(len(d) - 1) * statistics.stdev(d) / math.sqrt(len(d))
    return m, m - h, m + h, len(d)


def effect(a, cell, planner, endpoint):
    return next(e for e in a["endpoints"] if e["cell"] == cell and e["planner"] == planner
                and e["endpoint"] == endpoint and e["tested"])


def show_effect(e):
    ci = e["ci95"] or [None, None]
    return f"{fmt(e['mean_difference'])} [{fmt(ci[0])}, {fmt(ci[1])}], n = {e['n']}, " \
           f"**{klass(e)}**"


def klass(e):
    if e["verdict"] == "relevant":
        return "relevant " + ("−" if e["mean_difference"] < 0 else "+")
    return e["verdict"]


def show_pair(p, delta):
    if p is None:
        return "– (fewer than 2 pairs)", None
    m, lo, hi, n = p
    v = verdict(m, lo, hi, delta) if delta else ("earlier" if hi < 0 else
                                                  "later" if lo > 0 else "no order shown")
    return f"{fmt(m)} [{fmt(lo)}, {fmt(hi)}], n = {n}, **{v}**", v


def holds(k):
    return {"relevant −": "holds", "negligible": "does not hold",
            "relevant +": "reversed"}.get(k, "not shown")


def main():
    rep = Path(sys.argv[1]) if len(sys.argv) > 1 else \
        Path(__file__).resolve().parent / "comparison.report"
    if not (rep / "report.json").is_file():
        print(f"error: {rep / 'report.json'}: missing (run `merge_sim study "
              f"docs/studies/paper_comparison/comparison.toml`)", file=sys.stderr)
        sys.exit(2)
    report = json.loads((rep / "report.json").read_text())
    rows = [json.loads(x) for x in (rep / "rows.jsonl").read_text().splitlines() if x]
    a = report["analysis"]
    p = report["provenance"]
    print(f"plan blob `{p['plan_blob']}`, added in `{p['plan_added_in']}`, simulator "
          f"`{p['simulator_commit']}`, {'exploratory' if p['exploratory'] else 'confirmatory'}\n")
    for cell, label in enumerate(report["cells"]):
        print(f"## {label}\n")
        print("| claim | measure | result | decision |")
        print("|---|---|---|---|")
        iso = effect(a, cell, ISO, PEAK)
        print(f"| C1 PF-ISO calms the obstacle | ISO − CS, obstacle peak \\|r\\| (rad/s) | "
              f"{show_effect(iso)} | {holds(klass(iso))} |")
        text, v = show_pair(paired(rows, cell, ISO, SP, PEAK), DELTA_R)
        print(f"| C2 more than PF-SP | ISO − SP, obstacle peak \\|r\\| (rad/s) | {text} | "
              f"{holds(v)} |")
        ms = effect(a, cell, ISO, MIN_SPEED)
        n_slow = sum(1 for r in rows if r["cell"] == cell and r["planner"] == ISO
                     and r["status"] == "completed"
                     and r["endpoints"][ONSET]["pre_contact"] is not None)
        n_all = sum(1 for r in rows if r["cell"] == cell and r["planner"] == ISO
                    and r["status"] == "completed")
        on_text, on_v = show_pair(paired(rows, cell, ISO, SP, ONSET), None)
        ok = (ms["ci95"] is not None and ms["ci95"][1] < 0) and n_slow >= 0.5 * n_all \
            and on_v == "earlier"
        print(f"| C3 PF-ISO's obstacle slows early | (a) ISO − CS lowest speed; (b) slows / n; "
              f"(c) ISO − SP onset (s) | (a) {show_effect(ms)}; (b) {n_slow} / {n_all}; "
              f"(c) {on_text} | {'holds' if ok else 'does not hold'} |")
        pr_text, pr_v = show_pair(paired(rows, cell, ISO, PRED, ONSET), None)
        print(f"| C4 V2V makes it early | ISO − PRED onset (s), where both slow | {pr_text} | "
              f"{'holds' if pr_v == 'earlier' else 'does not hold'} |")
        ego = effect(a, cell, ISO, EGO_PEAK)
        print(f"| C5 the ego is calmer with PF-ISO | ISO − CS, ego peak \\|r\\| (rad/s) | "
              f"{show_effect(ego)} | {holds(klass(ego))} |")
        eq10 = effect(a, cell, EQ10, PEAK)
        print(f"| control: Eq. 10 with w3 = 0 moves nothing | EQ10 − CS, obstacle peak \\|r\\| | "
              f"{show_effect(eq10)} | {'passes' if klass(eq10) == 'negligible' else 'fails'} |")
        for planner in (SP, ISO, PRED, EQ10):
            c = next(c for c in a["collisions"] if c["cell"] == cell and c["planner"] == planner)
            print(f"| C6 no collisions ({planner}) | runs with a contact, {planner} / PF-CS; "
                  f"McNemar; difference in proportions | {c['both'] + c['only_planner']} / "
                  f"{c['both'] + c['only_reference']} of {c['n']}; p = {fmt(c['p_mcnemar'], 3)}; "
                  f"{fmt(c['difference'], 3)} [{fmt(c['ci95'][0], 3)}, {fmt(c['ci95'][1], 3)}] | "
                  f"{'holds' if c['both'] + c['only_planner'] == 0 else 'does not hold'} |")
        print()


if __name__ == "__main__":
    main()
