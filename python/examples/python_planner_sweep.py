# %% [markdown]
# # A planner written in Python, in a sweep beside the paper's planners
#
# `LaneKeepingCruise` keeps the centreline of the lane it is in at its target speed, but never
# closes in on a vehicle ahead in that lane faster than a 1.5 s time gap allows. Registered
# under a name, it runs wherever a planner name goes; here in a paired sweep with PF-CS and
# PF-ISO on the urgent merge (every vehicle driven by the swept planner), its rows beside theirs.
# It never changes lanes on purpose, so the merging ego drives into the end of its lane (the road
# edge): its rows show the collision the PF planners avoid.
# Run as a script (`python examples/python_planner_sweep.py [RUNS]`) or cell by cell.

# %%
import sys

import mergesim

RUNS = int(sys.argv[1]) if len(sys.argv) > 1 else 20
NAME = "lane-keeping-cruise"


class LaneKeepingCruise:
    """Lane keeping with a constant time gap to the vehicle ahead (python/README.md,
    "Planners in Python", lists the observation's keys)."""

    time_gap_s = 1.5
    min_gap_m = 2.0
    step_m = 4.0
    points = 20

    def plan(self, obs):
        road, lane, ego = obs["road"], obs["lane"], obs["ego"]
        half_width_m = 0.5 * lane["width_m"]
        # The nearest vehicle ahead in this lane (or within a metre of entering it).
        speed_mps = obs["target_speed_mps"]
        for other in obs["neighbours"]:
            s_m, d_m = road.project(lane["id"], other["state"]["x_m"], other["state"]["y_m"])
            gap_m = s_m - lane["s_m"] - 0.5 * (other["shape"]["length_m"] + obs["ego_shape"]["length_m"])
            if s_m > lane["s_m"] and abs(d_m) < half_width_m + 1.0:
                keeps_gap_mps = max(gap_m - self.min_gap_m, 0.0) / self.time_gap_s
                speed_mps = min(speed_mps, max(keeps_gap_mps, other["state"]["speed_mps"]))
        speed_mps = max(speed_mps, 0.5)
        # Points along the lane's centreline, timed at that speed.
        ahead = road.centreline(
            lane["id"], lane["s_m"] + self.step_m, lane["s_m"] + self.points * self.step_m, self.step_m
        )
        t0 = obs["time_s"]
        path = [(ego["x_m"], ego["y_m"], speed_mps, t0)]
        path += [(x, y, speed_mps, t0 + self.step_m * (i + 1) / speed_mps) for i, (x, y) in enumerate(ahead)]
        return {"path": path, "broadcast": True}


mergesim.register_planner(NAME, LaneKeepingCruise)

# %% The sweep: the same instances for every planner, in parallel in Rust (the Python planner's
# cycles take the GIL one at a time).
rows = mergesim.sweep("urgent_merge", planners=["pf-cs", "pf-iso", NAME], runs=RUNS, seed=2024)
print(rows.groupby("planner", sort=False)[["collisions", "min_gap_m", "tet_s", "ego.min_speed_mps"]].mean())
print(rows.groupby("planner", sort=False)["status"].value_counts())
