"""What a planning cycle of a Python planner costs, next to the built-in PF-ISO.

Every planner-driven vehicle of a scenario is driven by the planner under test (``planner=``);
the simulator times each ``Behaviour::plan`` call (wall clock, µs) and reports the median and
the 99th percentile over the run in ``summary["planner_stats"]`` (``p50_plan_us``,
``p99_plan_us``). For a Python planner that time holds everything the adapter does: taking the
GIL, building the observation dict, calling ``plan``, and checking and converting the path.
Each (scenario, planner) pair runs ``REPEATS`` times; the figures printed are the medians over
the repeats.

    python benchmarks/planner_cost.py [REPEATS]

``mergesim.run`` plans the vehicles of a world in parallel, one worker per core: Python
planners then take turns with the GIL, and a cycle's time includes any wait for it.
"""

import statistics
import sys

import mergesim

REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 5


class Null:
    """The adapter's own cost: a two-point straight path, no work in Python."""

    def plan(self, obs):
        e, v, t = obs["ego"], max(obs["target_speed_mps"], 0.5), obs["time_s"]
        return [(e["x_m"], e["y_m"], v, t), (e["x_m"] + 50.0, e["y_m"], v, t + 50.0 / v)]


class LaneCruise:
    """A trivial planner: its lane's centreline, 20 points 4 m apart, at its target speed."""

    def plan(self, obs):
        road, lane, e = obs["road"], obs["lane"], obs["ego"]
        v, t = max(obs["target_speed_mps"], 0.5), obs["time_s"]
        ahead = road.centreline(lane["id"], lane["s_m"] + 4.0, lane["s_m"] + 80.0, 4.0)
        return [(e["x_m"], e["y_m"], v, t)] + [
            (x, y, v, t + 4.0 * (i + 1) / v) for i, (x, y) in enumerate(ahead)
        ]


mergesim.register_planner("py-null", Null)
mergesim.register_planner("py-lane-cruise", LaneCruise)

print("scenario        planner         cycles  p50_us  p99_us")
for scenario in ("urgent_merge", "dense_merge"):
    for planner in ("py-null", "py-lane-cruise", "pf-iso"):
        p50, p99, plans = [], [], 0
        for _ in range(REPEATS):
            stats = mergesim.run(scenario, planner=planner).summary["planner_stats"]
            p50.append(stats["p50_plan_us"])
            p99.append(stats["p99_plan_us"])
            plans = stats["plans"]
        print(f"{scenario:15} {planner:15} {plans:6d} {statistics.median(p50):7.1f} "
              f"{statistics.median(p99):7.1f}")
