"""mergesim.register_planner: a planner written in Python runs in run, a scenario's driver, sweep,
study and MergeEnv; its failures end its run, not the process; bad names are refused."""

from __future__ import annotations

import math
import pathlib
import subprocess
import sys
from typing import Any, Dict, List

import numpy as np
import pandas as pd
import pytest

import mergesim

from conftest import REPO, SHORT

CRUISE = "py-cruise-test"
EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "python_planner_sweep.py"


class Cruise:
    """Keeps its lane's centreline at its target speed; remembers what it saw."""

    seen: List[Dict[str, Any]] = []

    def plan(self, obs: Dict[str, Any]) -> Dict[str, Any]:
        Cruise.seen.append(obs)
        road, lane = obs["road"], obs["lane"]
        v = max(obs["target_speed_mps"], 0.5)
        t0, ego = obs["time_s"], obs["ego"]
        points = road.centreline(lane["id"], lane["s_m"] + 4.0, lane["s_m"] + 80.0, 4.0)
        path = [(ego["x_m"], ego["y_m"], v, t0)]
        path += [(x, y, v, t0 + 4.0 * (i + 1) / v) for i, (x, y) in enumerate(points)]
        return {"path": path, "broadcast": True}


class Boom:
    def plan(self, obs: Dict[str, Any]) -> Any:
        if obs["time_s"] >= 0.3:
            raise ValueError("boom at t = 0.3")
        return Cruise().plan(obs)


@pytest.fixture(autouse=True)
def registered():
    """The planners of this module, registered for each test and removed after it (the table is
    process-wide: other test modules compare planner lists with the CLI's)."""
    Cruise.seen = []
    mergesim.register_planner(CRUISE, Cruise)
    mergesim.register_planner("py-boom-test", Boom)
    yield
    for name in mergesim.python_planners():
        mergesim.unregister_planner(name)


def test_listed_with_the_built_ins() -> None:
    assert CRUISE in mergesim.planners()
    assert "pf-iso" in mergesim.planners()
    assert mergesim.python_planners() == ["py-boom-test", CRUISE]
    mergesim.unregister_planner(CRUISE)
    assert CRUISE not in mergesim.planners()


def test_runs_in_run_and_sees_its_observation() -> None:
    result = mergesim.run("urgent_merge", planner=CRUISE, params=SHORT)
    assert result.summary["planner"] == CRUISE
    # Two vehicles, 2 s at 10 Hz: 20 cycles each (the simulator counts them).
    assert result.summary["planner_stats"]["plans"] == 40
    assert len(Cruise.seen) == 40
    assert not result.time_series.empty
    by_vehicle: Dict[str, List[Dict[str, Any]]] = {}
    for obs in Cruise.seen:
        by_vehicle.setdefault(obs["ego_name"], []).append(obs)
    assert sorted(by_vehicle) == ["ego", "obstacle"]
    for name, seen in by_vehicle.items():
        times = [o["time_s"] for o in seen]
        assert np.allclose(np.diff(times), 0.1), name
        first = seen[0]
        assert set(first) == {
            "time_s", "ego_id", "ego_name", "ego", "ego_shape", "target_speed_mps", "mu",
            "lane", "neighbours", "shared_paths", "road",
        }
        assert set(first["ego"]) == {"x_m", "y_m", "yaw_rad", "speed_mps"}
        assert first["ego_shape"]["length_m"] > first["ego_shape"]["width_m"] > 0
        assert first["lane"]["id"] in first["road"].lane_ids()
        assert abs(first["lane"]["d_m"]) < first["lane"]["width_m"]
        assert [n["id"] for n in first["neighbours"]] == [1 - first["ego_id"]]
        # Both are connected: from the second cycle on each hears the other's broadcast path.
        assert [m["sender"] for m in seen[1]["shared_paths"]] == [1 - first["ego_id"]]
        assert len(seen[1]["shared_paths"][0]["points"][0]) == 3
        # The vehicle follows its path: it keeps its lane (within 0.5 m of the centreline).
        assert max(abs(o["lane"]["d_m"]) for o in seen) < 0.5, name
    ego = result.time_series[result.time_series["vehicle"] == "ego"]
    assert ego["speed_mps"].iloc[-1] > 0.5 * ego["speed_mps"].iloc[0]


def test_the_road_helper() -> None:
    mergesim.run("urgent_merge", planner=CRUISE, params={"sim": {"duration_s": 0.2}})
    obs = Cruise.seen[0]
    road, lane = obs["road"], obs["lane"]
    x_m, y_m = road.point(lane["id"], lane["s_m"], lane["d_m"])
    assert math.hypot(x_m - obs["ego"]["x_m"], y_m - obs["ego"]["y_m"]) < 1e-6
    assert road.nearest_lane(obs["ego"]["x_m"], obs["ego"]["y_m"])[0] == lane["id"]
    assert road.project(lane["id"], x_m, y_m) == pytest.approx((lane["s_m"], lane["d_m"]))
    assert len(road.centreline(lane["id"], 0.0, 10.0, 2.5)) == 5
    with pytest.raises(mergesim.ScenarioError, match="not a lane of this road"):
        road.point(999, 0.0)
    with pytest.raises(mergesim.ScenarioError, match="step_m > 0"):
        road.centreline(lane["id"], 0.0, 10.0, 0.0)


def test_runs_as_a_scenario_driver() -> None:
    text = (REPO / "scenarios" / "builtin" / "urgent_merge.toml").read_text()
    assert text.count('driver = { planner = "pf-iso" }') == 2
    # The obstacle (the second vehicle) driven by the Python planner, the ego by PF-ISO.
    head, tail = text.rsplit('driver = { planner = "pf-iso" }', 1)
    text = head + f'driver = {{ planner = "{CRUISE}" }}' + tail
    result = mergesim.run(text, params=SHORT)
    assert result.summary["planner"] == "mixed"
    assert {o["ego_name"] for o in Cruise.seen} == {"obstacle"}
    assert len(Cruise.seen) == 20


def test_sweep_beside_pf_cs_same_rows_whatever_the_threads() -> None:
    planners = ["pf-cs", CRUISE]
    one = mergesim.sweep("urgent_merge", planners=planners, runs=3, seed=7, params=SHORT, threads=1)
    two = mergesim.sweep("urgent_merge", planners=planners, runs=3, seed=7, params=SHORT, threads=2)
    assert list(one["planner"]) == planners * 3
    assert (one["status"] == "completed").all()
    for column in ["min_gap_m", "tet_s", "collisions", "ego.min_speed_mps", "obstacle.min_speed_mps"]:
        assert one[column].notna().all(), column
    assert (one["planners"] == tuple(planners)).all()
    pd.testing.assert_frame_equal(one.drop(columns="wall_time_s"), two.drop(columns="wall_time_s"))
    # The Python planner's rows are its own runs, not pf-cs's.
    cruise, pf_cs = (one[one["planner"] == p].set_index("instance") for p in planners)
    assert (cruise["seed"] == pf_cs["seed"]).all()
    assert (cruise["ego.min_speed_mps"] != pf_cs["ego.min_speed_mps"]).any()


def test_runs_in_a_study(tmp_path: pathlib.Path) -> None:
    plan = tmp_path / "plan.toml"
    plan.write_text(
        f"""name = "py_planner_study"
scenario = "urgent_merge"
planners = ["pf-cs", "{CRUISE}"]
reference = "pf-cs"

[instances]
n = 2
seed = 5

[factors]
"sim.duration_s" = [2.0]

[endpoints]
primary = {{ figure = "ego.min_speed_mps", threshold = "0.5 m/s" }}
"""
    )
    tables = mergesim.study(plan, threads=1)
    endpoints = tables["endpoints"]
    assert set(endpoints["planner"]) == {CRUISE}
    assert (endpoints["n"] == 2).all()
    # 2 instances, 2 vehicles, 20 cycles each.
    assert len(Cruise.seen) == 80


def test_neighbours_planner_in_merge_env() -> None:
    env = mergesim.MergeEnv("urgent_merge", planner=CRUISE, params=SHORT)
    env.reset(seed=3)
    for _ in range(5):
        _, _, terminated, truncated, info = env.step(np.array([20.0, -3.5], dtype=np.float32))
        assert "error" not in info
        assert not (terminated or truncated)
    # The agent is the ego; its neighbour (the obstacle) plans in Python, once per step (and
    # once at the start).
    assert {o["ego_name"] for o in Cruise.seen} == {"obstacle"}
    assert len(Cruise.seen) == 5
    # The agent's commanded path is broadcast: the neighbour hears it.
    assert [m["sender"] for m in Cruise.seen[-1]["shared_paths"]] == [env.agent]


def test_exception_fails_the_run_not_the_process() -> None:
    expected = "Python planner 'py-boom-test': ValueError: boom at t = 0.3"
    with pytest.raises(mergesim.SimulationError, match="boom at t = 0.3") as raised:
        mergesim.run("urgent_merge", planner="py-boom-test", params=SHORT)
    assert expected in str(raised.value)
    assert "test_python_planner.py" in str(raised.value)
    rows = mergesim.sweep("urgent_merge", planners=["pf-cs", "py-boom-test"], runs=2, params=SHORT)
    # The library's status of any run that failed is "diverged"; the error says why.
    assert list(rows["status"]) == ["completed", "diverged"] * 2
    failed = rows[rows["status"] == "diverged"]
    assert failed["error"].str.contains(expected, regex=False).all()
    env = mergesim.MergeEnv("urgent_merge", planner="py-boom-test", params=SHORT)
    env.reset(seed=0)
    for _ in range(10):
        _, _, terminated, _, info = env.step(np.array([20.0, -3.5], dtype=np.float32))
        if terminated:
            break
    assert terminated and expected in info["error"]


@pytest.mark.parametrize(
    "returned, message",
    [
        ([], "the path is empty"),
        (None, "plan() returned None"),
        ({"broadcast": True}, 'no "path"'),
        ([(0.0, 0.0, 1.0, 1.0), (1.0, 0.0, 1.0, 1.0)], "path[1].t_s = 1: not after path[0].t_s = 1"),
        ([(0.0, float("nan"), 1.0, 1.0)], "path[0].y_m = NaN: not finite"),
        ([(0.0, 0.0, -1.0, 1.0)], "path[0].speed_mps = -1: must be ≥ 0"),
        ([(0.0, 0.0, 1.0)], "path[0]: need 4 numbers"),
        ([{"x_m": 0.0, "y_m": 0.0, "t_s": 1.0}], 'path[0]: no key "speed_mps"'),
        ("fast", "path[0]: need a dict"),
        ({"path": [(0.0, 0.0, 1.0, 1.0)], "broadcast": "yes"}, "broadcast"),
    ],
)
def test_bad_decision_is_a_clear_error(returned: Any, message: str) -> None:
    class Bad:
        def plan(self, obs: Dict[str, Any]) -> Any:
            return returned

    mergesim.register_planner("py-bad-test", Bad)
    with pytest.raises(mergesim.SimulationError) as raised:
        mergesim.run("urgent_merge", planner="py-bad-test", params=SHORT)
    assert "Python planner 'py-bad-test': " in str(raised.value)
    assert message in str(raised.value)


def test_dict_points_and_no_broadcast() -> None:
    class Quiet:
        def plan(self, obs: Dict[str, Any]) -> Any:
            path = Cruise().plan(obs)["path"]
            keys = ("x_m", "y_m", "speed_mps", "t_s")
            return {"path": [dict(zip(keys, p)) for p in path], "broadcast": False}

    mergesim.register_planner("py-quiet-test", Quiet)
    text = (REPO / "scenarios" / "builtin" / "urgent_merge.toml").read_text()
    head, tail = text.rsplit('driver = { planner = "pf-iso" }', 1)
    text = head + 'driver = { planner = "py-quiet-test" }' + tail
    text = text.replace('driver = { planner = "pf-iso" }', f'driver = {{ planner = "{CRUISE}" }}')
    result = mergesim.run(text, params=SHORT)
    assert result.summary["planner_stats"]["plans"] == 40
    # The quiet obstacle broadcasts nothing: the ego (the Cruise) hears nobody, while the
    # obstacle (which plans through a Cruise too) hears the ego.
    seen = {name: [o for o in Cruise.seen if o["ego_name"] == name] for name in ("ego", "obstacle")}
    assert len(seen["ego"]) == len(seen["obstacle"]) == 20
    assert all(o["shared_paths"] == [] for o in seen["ego"])
    assert all(len(o["shared_paths"]) == 1 for o in seen["obstacle"][1:])


def test_a_failing_factory_is_a_clear_error() -> None:
    def factory() -> Any:
        raise RuntimeError("no planner today")

    mergesim.register_planner("py-nofactory-test", factory)
    with pytest.raises(mergesim.ScenarioError, match="creating it failed: RuntimeError: no planner today"):
        mergesim.run("urgent_merge", planner="py-nofactory-test", params=SHORT)


@pytest.mark.parametrize(
    "name, factory, match",
    [
        ("pf-iso", Cruise, 'planner name "pf-iso" is already registered'),
        ("external", Cruise, 'planner name "external" is already registered'),
        (CRUISE, Cruise, f'planner name "{CRUISE}" is already registered'),
        ("my planner", Cruise, "without spaces, commas or quotes"),
        ("", Cruise, "must be non-empty"),
        ("a,b", Cruise, "without spaces, commas or quotes"),
        ("x", 42, "must be callable"),
        ("x", int, "has no plan"),
        (7, Cruise, "must be a string"),
    ],
)
def test_bad_or_taken_names_are_refused(name: Any, factory: Any, match: str) -> None:
    with pytest.raises(mergesim.ScenarioError, match=match):
        mergesim.register_planner(name, factory)
    assert mergesim.python_planners() == ["py-boom-test", CRUISE]


def test_unregister_an_unknown_name() -> None:
    with pytest.raises(mergesim.ScenarioError, match="not a registered Python planner"):
        mergesim.unregister_planner("pf-iso")


def test_unknown_planner_lists_the_python_ones() -> None:
    with pytest.raises(mergesim.ScenarioError) as raised:
        mergesim.run("urgent_merge", planner="nope")
    assert str(raised.value) == (
        "unknown planner 'nope'; valid: idm-mobil, pf-cs, pf-iso, pf-iso-pred, pf-iso-seq, pf-sp, "
        f"pf-sp-eq10, py-boom-test, {CRUISE}"
    )


def test_python_planner_sweep_example(tmp_path: pathlib.Path) -> None:
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "2"], check=True, cwd=tmp_path, capture_output=True, text=True
    )
    assert "lane-keeping-cruise" in done.stdout
    assert "completed" in done.stdout
