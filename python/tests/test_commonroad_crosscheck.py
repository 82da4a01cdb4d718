"""Cross-check of mergesim's CommonRoad reader against commonroad-io's, for every test file in
tests/data/commonroad: lanelet vertices and links, obstacle shapes and states (positions,
orientations, velocities, times) and the planning problems.

Our side is `merge_sim commonroad dump FILE` (JSON). Both readers parse the same decimal text
into IEEE doubles, so values must agree to the last bit; the tolerance, 1e-12 relative
(+1e-12 absolute for zeros), only allows for a different decimal-to-binary path (none is
expected: Rust's and Python's float parsing are both correctly rounded). Times: time step ×
timeStepSize, computed the same way on both sides.
"""

import json
import math
import os
import pathlib
import subprocess

import pytest
from commonroad.common import file_reader as cr_reader  # commonroad-io, pinned in ci.sh

DATA = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "commonroad"
FILES = sorted(DATA.glob("*.xml"))
REL = 1e-12


def close(a, b):
    return math.isclose(float(a), float(b), rel_tol=REL, abs_tol=REL)


def dump(path):
    exe = os.environ.get("MERGESIM_BIN", "merge_sim")
    out = subprocess.run(
        [exe, "commonroad", "dump", str(path)], check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout)


def value_of(ours):
    """(start, end) of our JSON value {"exact": v} or {"interval": {...}}."""
    if "exact" in ours:
        return ours["exact"], ours["exact"]
    return ours["interval"]["start"], ours["interval"]["end"]


def check_value(theirs, ours, what):
    assert ours is not None, what
    lo, hi = value_of(ours)
    if hasattr(theirs, "start"):
        assert close(theirs.start, lo) and close(theirs.end, hi), (what, theirs, ours)
    else:
        assert lo == hi and close(theirs, lo), (what, theirs, ours)


def check_position(theirs, ours, what):
    if hasattr(theirs, "rect_center"):  # RectOccupancy: an uncertain position
        (rect,) = [s["rectangle"] for s in ours["shapes"]]
        assert close(theirs.rect_center.x, rect["center_m"][0]), what
        assert close(theirs.rect_center.y, rect["center_m"][1]), what
        assert close(theirs.length, rect["length_m"]) and close(theirs.width, rect["width_m"])
        assert close(theirs.orientation, rect["orientation_rad"]), what
    elif hasattr(theirs, "center"):  # goal Rectangle shape
        (rect,) = [s["rectangle"] for s in ours["shapes"]]
        assert close(theirs.center[0], rect["center_m"][0]), what
        assert close(theirs.center[1], rect["center_m"][1]), what
        assert close(theirs.length, rect["length_m"]) and close(theirs.width, rect["width_m"])
        assert close(theirs.orientation, rect["orientation_rad"]), what
    else:
        assert close(theirs[0], ours["point"][0]) and close(theirs[1], ours["point"][1]), what


def check_state(theirs, ours, what):
    check_value(theirs.time_step, ours["time_step"], what + " time")
    for attr, key in [
        ("orientation", "orientation_rad"),
        ("velocity", "velocity_mps"),
    ]:
        if getattr(theirs, attr, None) is not None:
            check_value(getattr(theirs, attr), ours[key], f"{what} {attr}")
    if getattr(theirs, "position", None) is not None:
        check_position(theirs.position, ours["position"], what + " position")


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_reading_matches_commonroad_io(path):
    scenario, problems = cr_reader.CommonRoadFileReader(str(path)).open()
    ours = dump(path)
    sc = ours["scenario"]
    assert close(scenario.dt, sc["time_step_s"])

    # Lanelets: every vertex and link.
    lanelets = {l["id"]: l for l in sc["lanelets"]}
    assert sorted(lanelets) == sorted(l.lanelet_id for l in scenario.lanelet_network.lanelets)
    vertices = 0
    for l in scenario.lanelet_network.lanelets:
        o = lanelets[l.lanelet_id]
        for theirs, mine in [(l.left_vertices, o["left_bound_m"]), (l.right_vertices, o["right_bound_m"])]:
            assert len(theirs) == len(mine), l.lanelet_id
            for p, q in zip(theirs, mine):
                assert close(p[0], q[0]) and close(p[1], q[1]), (l.lanelet_id, p, q)
                vertices += 1
        assert sorted(l.successor) == sorted(o["successors"])
        assert sorted(l.predecessor) == sorted(o["predecessors"])
        for side, same in [("left", l.adj_left_same_direction), ("right", l.adj_right_same_direction)]:
            adj = getattr(l, "adj_" + side)
            mine = o["adjacent_" + side]
            if adj is None:
                assert mine is None
            else:
                assert mine["id"] == adj
                assert mine["driving_dir"] == ("same" if same else "opposite")
    assert vertices > 0

    # Obstacles: shape, initial state, every trajectory state, and our replay times.
    obstacles = {o["id"]: o for o in sc["dynamic_obstacles"] + sc["static_obstacles"]}
    theirs_all = list(scenario.dynamic_obstacles) + list(scenario.static_obstacles)
    assert sorted(obstacles) == sorted(o.obstacle_id for o in theirs_all)
    states = 0
    for t in theirs_all:
        o = obstacles[t.obstacle_id]
        rect = o["shape"]["rectangle"]
        assert close(t.obstacle_shape.length, rect["length_m"])
        assert close(t.obstacle_shape.width, rect["width_m"])
        check_state(t.initial_state, o["initial_state"], f"obstacle {t.obstacle_id} initial")
        their_states = t.prediction.trajectory.state_list if t.prediction is not None else []
        assert len(their_states) == len(o["trajectory"])
        for k, (a, b) in enumerate(zip(their_states, o["trajectory"])):
            check_state(a, b, f"obstacle {t.obstacle_id} state {k}")
            states += 1
        replay = ours["replay"][str(t.obstacle_id)]
        for a, r in zip([t.initial_state] + list(their_states), replay):
            assert close(a.time_step * scenario.dt, r["time_s"])
    assert states > 0

    # Planning problems: initial state and goal states.
    pps = {p["id"]: p for p in sc["planning_problems"]}
    assert sorted(pps) == sorted(problems.planning_problem_dict)
    for pid, p in problems.planning_problem_dict.items():
        o = pps[pid]
        check_state(p.initial_state, o["initial_state"], f"problem {pid} initial")
        assert len(p.goal.state_list) == len(o["goal_states"])
        for g, mine in zip(p.goal.state_list, o["goal_states"]):
            check_state(g, mine, f"problem {pid} goal")
