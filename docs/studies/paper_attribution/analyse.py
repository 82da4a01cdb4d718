#!/usr/bin/env python3
"""Tables and decisions of the paper-set attribution (README.md in this folder), from the report
that `merge_sim study attribution.toml` writes beside the plan (attribution.report/).

Fixed with the plan, before any of its runs. It reads report.json (paired effects, collisions)
and rows.jsonl (slowing onsets) and prints Markdown on stdout:

1. per cell (arm): the readings; PF-ISO - PF-CS on the obstacle's lowest speed and on its peak
   yaw rate (mean, 95 % CI, verdict), and PF-SP - PF-CS on the peak yaw rate; runs with a
   contact per planner;
2. per cell: how many PF-ISO and PF-SP obstacles slow (a slowing onset, 0.1 m/s below the
   target, before the run's first contact: the pre-contact value), their median onset, and
   PF-ISO - PF-SP over the instances where both slow (mean, 95 % t-interval, n);
3. per cell, the protocol's decision "the obstacle slows early with PF-ISO": (a) the 95 % CI
   of PF-ISO - PF-CS on obstacle.min_speed_mps (pre-contact) lies entirely below 0, (b) PF-ISO's
   obstacle has a slowing onset in at least half of the instances, and (c) where both slow,
   PF-ISO's onset is earlier than PF-SP's (the 95 % t-interval of PF-ISO - PF-SP entirely
   below 0; fewer than 2 such pairs: not met). Then the literal arms' verdict on
   "the printed equations cannot produce that" (README.md, "Decision rule").

Usage: python3 docs/studies/paper_attribution/analyse.py [REPORT_DIR]
   (default: attribution.report beside this script). Exits 2 when the report is missing.
"""

import json
import math
import statistics
import sys
from pathlib import Path

ISO, CS, SP = "pf-iso", "pf-cs", "pf-sp"
ONSET = "obstacle.slowing_onset_s"
MIN_SPEED = "obstacle.min_speed_mps"
PEAK = "obstacle.max_abs_yaw_rate_radps"

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


def reading(label, key):
    part = [p for p in label.split(", ") if p.startswith(key + "=")]
    return part[0].split("=", 1)[1].strip('"') if part else "(set)"


def arm_name(label):
    if "interaction_weight=12.0" in label:
        return "paper set as published (w_R 39, w3 12)"
    slp = reading(label, "sim.planner.interaction_slp_reading")
    roles = "by side" if reading(label, "sim.planner.obstacle_min_distance_by_side") == "true" \
        else "printed"
    lateral = reading(label, "sim.planner.obstacle_lateral_form")
    return f"{slp}, roles {roles}, σ_y {lateral}"


def is_literal(label):
    """Printed D_min roles and the printed (unsquared) sigma_y, either U_SLP reading."""
    return ("interaction_weight=6.0" in label
            and reading(label, "sim.planner.obstacle_min_distance_by_side") == "false"
            and reading(label, "sim.planner.obstacle_lateral_form") == "printed-laplace")


def effect(a, cell, planner, endpoint):
    return next(e for e in a["endpoints"] if e["cell"] == cell and e["planner"] == planner
                and e["endpoint"] == endpoint)


def collided(a, cell, planner):
    c = next(c for c in a["collisions"] if c["cell"] == cell and c["planner"] == planner)
    return c["both"] + c["only_planner"], c["both"] + c["only_reference"]


def main():
    rep = Path(sys.argv[1]) if len(sys.argv) > 1 else \
        Path(__file__).resolve().parent / "attribution.report"
    if not (rep / "report.json").is_file():
        print(f"error: {rep / 'report.json'}: missing (run `merge_sim study "
              f"docs/studies/paper_attribution/attribution.toml`)", file=sys.stderr)
        sys.exit(2)
    report = json.loads((rep / "report.json").read_text())
    rows = [json.loads(x) for x in (rep / "rows.jsonl").read_text().splitlines() if x]
    a = report["analysis"]
    p = report["provenance"]
    print(f"plan blob `{p['plan_blob']}`, added in `{p['plan_added_in']}`, simulator "
          f"`{p['simulator_commit']}`, {'exploratory' if p['exploratory'] else 'confirmatory'}\n")

    print("| arm | ISO − CS, obstacle lowest speed (m/s), 95 % CI, verdict | ISO − CS, obstacle "
          "peak \\|r\\| (rad/s), 95 % CI, verdict | SP − CS, peak \\|r\\|, 95 % CI, verdict | "
          "runs with contact CS / SP / ISO |")
    print("|---|---|---|---|---|")
    for cell, label in enumerate(report["cells"]):
        ms, pk, sp = effect(a, cell, ISO, MIN_SPEED), effect(a, cell, ISO, PEAK), \
            effect(a, cell, SP, PEAK)
        iso_c, cs_c = collided(a, cell, ISO)
        sp_c, _ = collided(a, cell, SP)

        def e(x):
            ci = x["ci95"] or [None, None]
            return f"{fmt(x['mean_difference'])} [{fmt(ci[0])}, {fmt(ci[1])}], {x['verdict']}"
        print(f"| {arm_name(label)} | {e(ms)} | {e(pk)} | {e(sp)} | {cs_c} / {sp_c} / {iso_c} |")
    print()

    print("| arm | PF-ISO obstacle: slows / n, median onset (s) | PF-SP obstacle: slows / n, "
          "median onset (s) | ISO − SP onset where both slow: mean (s), 95 % CI, n | the "
          "obstacle slows early with PF-ISO (a ∧ b ∧ c) |")
    print("|---|---|---|---|---|")
    decisions = {}
    for cell, label in enumerate(report["cells"]):
        per = {}
        for r in rows:
            if r["cell"] == cell and r["status"] == "completed":
                per.setdefault(r["planner"], {})[r["instance"]] = \
                    r["endpoints"][ONSET]["pre_contact"]
        iso, sp = per.get(ISO, {}), per.get(SP, {})

        def summary(d):
            v = [x for x in d.values() if x is not None]
            return len(v), f"{len(v)} / {len(d)}, {fmt(statistics.median(v), 3) if v else '–'}"

        both = [iso[i] - sp[i] for i in iso
                if i in sp and iso[i] is not None and sp[i] is not None]
        c_ok = False
        if len(both) >= 2:
            m = statistics.fmean(both)
            h = t975(len(both) - 1) * statistics.stdev(both) / math.sqrt(len(both))
            paired = f"{fmt(m, 3)} [{fmt(m - h, 3)}, {fmt(m + h, 3)}], {len(both)}"
            c_ok = m + h < 0.0
        else:
            paired = f"– ({len(both)} pairs)"
        n_slow, iso_text = summary(iso)
        ms = effect(a, cell, ISO, MIN_SPEED)
        a_ok = ms["ci95"] is not None and ms["ci95"][1] < 0.0
        b_ok = len(iso) > 0 and n_slow >= 0.5 * len(iso)
        decisions[cell] = a_ok and b_ok and c_ok
        yn = {True: "yes", False: "no"}
        verdict = f"{yn[decisions[cell]]} (a: {yn[a_ok]}, b: {yn[b_ok]}, c: {yn[c_ok]})"
        print(f"| {arm_name(label)} | {iso_text} | {summary(sp)[1]} | {paired} | {verdict} |")
    print()

    literal = [c for c, lab in enumerate(report["cells"]) if is_literal(lab)]
    produced = [c for c in literal if decisions[c]]
    print("Literal arms (printed D_min roles, printed σ_y, either U_SLP reading): "
          + ", ".join(arm_name(report["cells"][c]) for c in literal) + ".")
    if produced:
        print("\n**Decision:** the obstacle slows early with PF-ISO in a literal arm ("
              + ", ".join(arm_name(report["cells"][c]) for c in produced)
              + "): \"the printed equations cannot produce that\" is **withdrawn**.")
    else:
        print("\n**Decision:** the obstacle does not slow early with PF-ISO in any literal arm: "
              "\"the printed equations cannot produce that\" **stands** for these readings.")


if __name__ == "__main__":
    main()
