#!/usr/bin/env python3
"""Summary tables of the paper-sensitivity study (README.md in this folder), from the six
reports that `merge_sim study <plan>.toml` writes beside the plans (<plan>.report/).

Fixed with the plans, before any of their runs. It only reads the reports (report.json for the
paired effects and collisions, rows.jsonl for the slowing onsets) and prints Markdown on stdout:

1. per plan, per cell: PF-ISO - PF-CS on the primary endpoint (mean, 95 % CI, verdict), the
   verdicts of the secondary endpoints, and collisions (runs with a contact, McNemar p, the
   paired difference in proportions with its 95 % CI);
2. per plan and parameter set: the decision of the protocol (README.md, "Decision rule"):
   "robust" when every level's class of the primary effect (relevant and its sign, negligible,
   inconclusive) equals the class at the value in use, else "sensitive", with the levels where
   it differs; the same for the collision comparison (McNemar p < 0.05 and its sign, or not);
3. the horizon plan only: the slowing onsets as a function of the horizon: per cell, the
   number of PF-ISO and PF-SP obstacles that slow (their onset is not null), their median
   onset, and the paired difference PF-ISO - PF-SP over the instances where both slow (mean,
   95 % t-interval, n). Onsets come from each run's whole-run value;
4. the look-ahead plan only: per parameter set and planner, the paired change of the obstacle's
   peak yaw rate (pre-contact) from look-ahead x 0.5 to x 2 on the same instances (mean, 95 %
   t-interval, n), and whether it falls by more than delta = 0.01 rad/s (its CI entirely below
   -delta): the protocol's test of "the look-ahead smooths the peaks" (decided on the paper
   set; the mergesim set's row is descriptive).

Usage: python3 docs/studies/paper_sensitivity/analyse.py [FOLDER]   (default: this folder)
Exits 2 naming the missing report when a report is absent.
"""

import json
import math
import statistics
import sys
from pathlib import Path

PLANS = [
    "interaction_floor",
    "horizon",
    "obstacle_start",
    "readings",
    "time_gaps",
    "tracker_lookahead",
]

# The value in use for each plan, as the cell label's factor = value pairs it must contain.
DEFAULTS = {
    "interaction_floor": ['sim.planner.interaction_floor=0.02'],
    "horizon": ['sim.planner.waypoint_count=20', 'sim.planner.step_time_s=0.4'],
    "obstacle_start": ['vehicles.obstacle.x_m=35.0'],
    "readings": ['sim.planner.interaction_rear_only=true',
                 'sim.planner.predict_obstacles_in_path=true'],
    "time_gaps": ['sim.planner.obstacle_time_gap_s=2.0',
                  'sim.planner.interaction_time_gap_s=2.0'],
    "tracker_lookahead": ['sim.tracker.lookahead_min_m=4.0'],
}

PRIMARY = "obstacle.max_abs_yaw_rate_radps"
ISO, CS, SP = "pf-iso", "pf-cs", "pf-sp"

# Two-sided 97.5 % quantiles of Student's t for small df (df > 30: the normal's 1.96 is off by
# under 2 %, so use the table up to 30 and a series beyond).
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
        2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
        2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def t975(df):
    if df <= 30:
        return T975[df - 1]
    # Cornish-Fisher expansion around z = 1.959964.
    z = 1.959964
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


def set_of(label):
    for s in ("paper", "mergesim"):
        if f'params="{s}"' in label:
            return s
    return "mergesim"


def plain(label):
    return label.replace('"', "").replace(" ", "")


def klass(e):
    v = e["verdict"]
    if v == "relevant":
        return "relevant " + ("−" if e["mean_difference"] < 0 else "+")
    return v


def collision_class(c):
    if c["p_mcnemar"] is not None and c["p_mcnemar"] < 0.05:
        return "fewer" if c["difference"] < 0 else "more"
    return "no difference shown"


def fmt(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


def load(folder, plan):
    rep = folder / f"{plan}.report"
    path = rep / "report.json"
    if not path.is_file():
        print(f"error: {path}: missing (run `merge_sim study {folder / plan}.toml`)",
              file=sys.stderr)
        sys.exit(2)
    report = json.loads(path.read_text())
    rows = [json.loads(line) for line in (rep / "rows.jsonl").read_text().splitlines() if line]
    return report, rows


def effects_table(plan, report):
    a = report["analysis"]
    print(f"### {plan}\n")
    p = report["provenance"]
    print(f"plan blob `{p['plan_blob']}`, added in `{p['plan_added_in']}`, simulator "
          f"`{p['simulator_commit']}`, {'exploratory' if p['exploratory'] else 'confirmatory'}\n")
    print("| cell | ISO − CS, obstacle peak \\|r\\| (rad/s), 95 % CI | n | verdict | "
          "secondary verdicts (obstacle β, obstacle v_min, ego \\|r\\|, min gap) | collisions "
          "ISO / CS | McNemar p | ISO − CS collision rate, 95 % CI |")
    print("|---|---|---|---|---|---|---|---|")
    for cell, label in enumerate(report["cells"]):
        prim = [e for e in a["endpoints"] if e["cell"] == cell and e["planner"] == ISO
                and e["endpoint"] == PRIMARY]
        sec = [e for e in a["endpoints"] if e["cell"] == cell and e["planner"] == ISO
               and e["role"] == "secondary" and e["tested"]
               and not e["endpoint"].endswith("slowing_onset_s")]
        col = [c for c in a["collisions"] if c["cell"] == cell and c["planner"] == ISO]
        e = prim[0]
        c = col[0]
        ci = e["ci95"] or [None, None]
        print(f"| {label} | {fmt(e['mean_difference'])} [{fmt(ci[0])}, {fmt(ci[1])}] | "
              f"{e['n']} | {klass(e)} | {', '.join(klass(s) for s in sec)} | "
              f"{c['both'] + c['only_planner']} / {c['both'] + c['only_reference']} | "
              f"{fmt(c['p_mcnemar'], 3)} | {fmt(c['difference'], 3)} "
              f"[{fmt(c['ci95'][0], 3)}, {fmt(c['ci95'][1], 3)}] |")
    print()


def decisions(plan, report):
    a = report["analysis"]
    out = []
    for s in ("paper", "mergesim"):
        cells = [i for i, lab in enumerate(report["cells"]) if set_of(lab) == s]
        if not cells:
            continue
        default = [i for i in cells
                   if all(d in plain(report["cells"][i]) for d in DEFAULTS[plan])]
        if len(default) != 1:
            print(f"error: {plan}: {len(default)} default cells in set {s}", file=sys.stderr)
            sys.exit(2)
        d = default[0]

        def prim(i):
            return next(e for e in a["endpoints"] if e["cell"] == i and e["planner"] == ISO
                        and e["endpoint"] == PRIMARY)

        def col(i):
            return next(c for c in a["collisions"] if c["cell"] == i and c["planner"] == ISO)

        ref_k, ref_c = klass(prim(d)), collision_class(col(d))
        diff_k = [report["cells"][i] for i in cells if klass(prim(i)) != ref_k]
        diff_c = [report["cells"][i] for i in cells if collision_class(col(i)) != ref_c]
        out.append((s, ref_k, diff_k, ref_c, diff_c))
    print(f"| {plan}: set | class at the value in use | primary | levels that differ | "
          "collisions at the value in use | collisions | levels that differ |")
    print("|---|---|---|---|---|---|---|")
    for s, rk, dk, rc, dc in out:
        print(f"| {s} | {rk} | {'sensitive' if dk else 'robust'} | {'; '.join(dk) or '–'} | "
              f"{rc} | {'sensitive' if dc else 'robust'} | {'; '.join(dc) or '–'} |")
    print()


def onsets(report, rows):
    print("### Slowing onsets against the horizon (whole run; the obstacle)\n")
    print("| cell | horizon (s) | PF-ISO: slow / n, median onset (s) | PF-SP: slow / n, median "
          "onset (s) | ISO − SP where both slow: mean (s), 95 % CI, n |")
    print("|---|---|---|---|---|")
    fig = "obstacle.slowing_onset_s"
    for cell, label in enumerate(report["cells"]):
        per = {}
        for r in rows:
            if r["cell"] == cell and r["status"] == "completed":
                per.setdefault(r["planner"], {})[r["instance"]] = r["endpoints"][fig]["whole_run"]
        iso, sp = per.get(ISO, {}), per.get(SP, {})
        lab = plain(label)
        n_wp = int(lab.split("waypoint_count=")[1].split(",")[0])
        dt = float(lab.split("step_time_s=")[1].split(",")[0])

        def summary(d):
            v = [x for x in d.values() if x is not None]
            return f"{len(v)} / {len(d)}, {fmt(statistics.median(v), 3) if v else '–'}"

        both = [iso[i] - sp[i] for i in iso if i in sp and iso[i] is not None
                and sp[i] is not None]
        if len(both) >= 2:
            m = statistics.fmean(both)
            h = t975(len(both) - 1) * statistics.stdev(both) / math.sqrt(len(both))
            paired = f"{fmt(m, 3)} [{fmt(m - h, 3)}, {fmt(m + h, 3)}], {len(both)}"
        else:
            paired = f"– ({len(both)} pairs)"
        print(f"| {label} | {n_wp * dt:.1f} | {summary(iso)} | {summary(sp)} | {paired} |")
    print()


def lookahead(report, rows):
    print("### The obstacle's peak yaw rate from look-ahead x 0.5 to x 2 (pre-contact)\n")
    print("| set | planner | x 0.5: mean (rad/s) | x 2: mean (rad/s) | change x 2 − x 0.5, "
          "95 % CI, n | falls by more than 0.01 rad/s |")
    print("|---|---|---|---|---|---|")
    delta = 0.01
    for s in ("paper", "mergesim"):
        cells = {}
        for i, lab in enumerate(report["cells"]):
            if set_of(lab) != s:
                continue
            if "lookahead_min_m=2.0" in plain(lab):
                cells["lo"] = i
            if "lookahead_min_m=8.0" in plain(lab):
                cells["hi"] = i
        for planner in (CS, ISO):
            val = {}
            for r in rows:
                if r["planner"] == planner and r["status"] == "completed":
                    val[(r["cell"], r["instance"])] = r["endpoints"][PRIMARY]["pre_contact"]
            lo = [val.get((cells["lo"], i)) for i in range(report["instances"])]
            hi = [val.get((cells["hi"], i)) for i in range(report["instances"])]
            pairs = [(a, b) for a, b in zip(lo, hi) if a is not None and b is not None]
            d = [b - a for a, b in pairs]
            m = statistics.fmean(d)
            h = t975(len(d) - 1) * statistics.stdev(d) / math.sqrt(len(d))
            falls = "yes" if m + h < -delta else "no"
            print(f"| {s} | {planner} | {fmt(statistics.fmean(a for a, _ in pairs))} | "
                  f"{fmt(statistics.fmean(b for _, b in pairs))} | {fmt(m)} [{fmt(m - h)}, "
                  f"{fmt(m + h)}], {len(d)} | {falls} |")
    print()


def main():
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    loaded = {plan: load(folder, plan) for plan in PLANS}
    print("## Effects per cell\n")
    for plan in PLANS:
        effects_table(plan, loaded[plan][0])
    print("## Decisions\n")
    for plan in PLANS:
        decisions(plan, loaded[plan][0])
    onsets(*loaded["horizon"])
    lookahead(*loaded["tracker_lookahead"])


if __name__ == "__main__":
    main()
