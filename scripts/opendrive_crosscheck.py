#!/usr/bin/env python3
"""Cross-checks mergesim's OpenDRIVE road against CommonRoad's own conversion.

Converts FILE.xodr with commonroad-scenario-designer (PyPI `commonroad-scenario-designer`, its
`opendrive_to_commonroad`), reads mergesim's road with `merge_sim opendrive dump FILE.xodr`, and
for every CommonRoad lanelet measures how far its centre vertices lie from the centreline of the
mergesim lane that runs the same way nearest to them, and how its width compares. Prints one
line per lanelet and the worst figures; exits 1 if a centre vertex lies more than --tol-m away.

Usage: python3 scripts/opendrive_crosscheck.py FILE.xodr [--merge-sim target/release/merge_sim]
"""
import argparse
import json
import math
import subprocess
import sys


def seg_dist(p, a, b):
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    L2 = dx * dx + dy * dy
    t = 0.0 if L2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / L2))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy), (dx, dy)


def nearest(p, direction, lanes):
    """Distance from p to the nearest centreline whose local direction agrees with `direction`,
    and that lane's width at the nearest vertex."""
    best = (math.inf, None)
    for lane in lanes:
        c = lane["centreline_m"]
        for i, (a, b) in enumerate(zip(c, c[1:])):
            d, (dx, dy) = seg_dist(p, a, b)
            if dx * direction[0] + dy * direction[1] <= 0:
                continue
            if d < best[0]:
                w = lane["left_width_m"][min(i, len(lane["left_width_m"]) - 1)]
                w += lane["right_width_m"][min(i, len(lane["right_width_m"]) - 1)]
                best = (d, w)
    return best


# CommonRoad lanelet types of lanes that mergesim does not take (not drivable by cars).
NOT_DRIVABLE = {"sidewalk", "crosswalk", "bicycleLane", "parking", "border", "shoulder",
                "driveWay", "restricted", "unknown"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("file")
    ap.add_argument("--merge-sim", default="target/release/merge_sim")
    ap.add_argument("--tol-m", type=float, default=0.05)
    args = ap.parse_args()
    from crdesigner.map_conversion.map_conversion_interface import opendrive_to_commonroad

    ours = json.loads(subprocess.run([args.merge_sim, "opendrive", "dump", args.file],
                                     check=True, capture_output=True, text=True).stdout)
    lanes = ours["lane_road"]["lanes"]
    scenario = opendrive_to_commonroad(args.file)
    worst_m, worst_width_m = 0.0, 0.0
    taken = 0
    for ll in scenario.lanelet_network.lanelets:
        types = {t.value for t in ll.lanelet_type}
        if types & NOT_DRIVABLE:
            continue
        taken += 1
        c = ll.center_vertices
        lane_worst, width_worst = 0.0, 0.0
        # Vertices closer than 1 cm to the previous kept one are skipped for the direction
        # (converted maps repeat a vertex at a join, sometimes 0.1 mm backwards).
        kept = [0]
        for i in range(1, len(c)):
            if math.dist(c[i], c[kept[-1]]) >= 0.01:
                kept.append(i)
        for n, i in enumerate(kept):
            if len(kept) < 2:
                break
            j, k = (kept[n + 1], i) if n + 1 < len(kept) else (i, kept[n - 1])
            direction = (c[j][0] - c[k][0], c[j][1] - c[k][1])
            d, ours_w = nearest((c[i][0], c[i][1]), direction, lanes)
            lane_worst = max(lane_worst, d)
            width = math.dist(ll.left_vertices[i], ll.right_vertices[i])
            if ours_w is not None:
                width_worst = max(width_worst, abs(width - ours_w))
        worst_m, worst_width_m = max(worst_m, lane_worst), max(worst_width_m, width_worst)
        print(f"lanelet {ll.lanelet_id}: {len(c)} centre vertices, farthest {lane_worst:.4f} m "
              f"from mergesim's centreline, width differs by at most {width_worst:.4f} m")
    print(f"worst: {worst_m:.4f} m (centre), {worst_width_m:.4f} m (width); "
          f"{taken} drivable lanelets of {len(scenario.lanelet_network.lanelets)}, "
          f"{len(lanes)} mergesim lanes")
    sys.exit(0 if worst_m <= args.tol_m else 1)


if __name__ == "__main__":
    main()
