"""mergesim.parallel_env: the PettingZoo contract, the agents, MergeEnv's observations and
reward terms, the team term, determinism, finished agents, the example."""

from __future__ import annotations

import pathlib
import subprocess
import sys
import warnings
from typing import Any, Dict, List

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test

import mergesim

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

from conftest import REPO, SHORT

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "parallel_env_random.py"
HOLD_LANE = np.array([20.0, -3.5], dtype=np.float32)
MERGE = np.array([20.0, 0.0], dtype=np.float32)


def _vehicles(scenario: str) -> List[Dict[str, Any]]:
    """A built-in scenario's ``[[vehicles]]``, from its TOML."""
    text = (REPO / "scenarios" / "builtin" / f"{scenario}.toml").read_text()
    return list(tomllib.loads(text)["vehicles"])


def connected_planner_vehicles(scenario: str) -> List[str]:
    """The names of a built-in scenario's connected, planner-driven vehicles, from its TOML."""
    return [
        v["name"]
        for v in _vehicles(scenario)
        if v.get("connected", True) and isinstance(v["driver"], dict) and "planner" in v["driver"]
    ]


def test_parallel_api_test_passes_without_warnings() -> None:
    env = mergesim.parallel_env(params=SHORT)
    with warnings.catch_warnings():
        # The API test reports some of its findings as warnings only.
        warnings.simplefilter("error")
        parallel_api_test(env, num_cycles=40)


def test_default_agents_are_the_connected_planner_driven_vehicles() -> None:
    expected = connected_planner_vehicles("urgent_merge")
    assert len(expected) == 2
    env = mergesim.parallel_env(params=SHORT)
    assert env.possible_agents == expected
    observations, infos = env.reset(seed=0)
    assert env.agents == expected and set(observations) == set(infos) == set(expected)
    # Human drivers (IDM, not connected) are not agents.
    mixed = connected_planner_vehicles("mixed_traffic")
    env = mergesim.parallel_env("mixed_traffic", params=SHORT)
    assert env.possible_agents == mixed
    assert len(mixed) < len(env.vehicle_names)


def test_spaces_are_merge_envs_and_the_same_object_every_call() -> None:
    single = mergesim.MergeEnv(params=SHORT, neighbours=3)
    env = mergesim.parallel_env(params=SHORT, neighbours=3)
    for agent in env.possible_agents:
        assert env.observation_space(agent) is env.observation_space(agent)
        assert env.action_space(agent) is env.action_space(agent)
        assert env.observation_space(agent) == single.observation_space
    assert env.action_space("ego") == single.action_space
    assert env.observation_names() == single.observation_names()


def test_one_chosen_agent_sees_and_earns_what_merge_env_does() -> None:
    """agents=["ego"] drives the world MergeEnv drives: the same observations, and the own
    reward is MergeEnv's reward (the team term comes on top)."""
    env = mergesim.parallel_env(agents=["ego"], params=SHORT)
    single = mergesim.MergeEnv(params=SHORT)
    assert env.possible_agents == ["ego"]
    observations, _ = env.reset(seed=4)
    obs, _ = single.reset(seed=4)
    np.testing.assert_array_equal(observations["ego"], obs)
    weights = env.team_weights
    for step in range(20):
        action = HOLD_LANE if step < 8 else MERGE
        observations, rewards, terminations, truncations, infos = env.step({"ego": action})
        obs, reward, terminated, truncated, info = single.step(action)
        np.testing.assert_array_equal(observations["ego"], obs)
        assert infos["ego"]["own_reward"] == reward
        assert infos["ego"]["team_reward"] == pytest.approx(
            weights.progress * infos["ego"]["progress"]
        )
        assert rewards["ego"] == reward + infos["ego"]["team_reward"]
        assert (terminations["ego"], truncations["ego"]) == (terminated, truncated)
        if terminated or truncated:
            break
    assert truncated and env.agents == []


def test_bad_agents_are_refused_naming_the_valid_ones() -> None:
    valid = ", ".join(connected_planner_vehicles("urgent_merge"))
    with pytest.raises(mergesim.ScenarioError, match=f"agent \"nobody\".*{valid}"):
        mergesim.parallel_env(agents=["ego", "nobody"])
    with pytest.raises(mergesim.ScenarioError, match="listed twice"):
        mergesim.parallel_env(agents=["ego", "ego"])
    with pytest.raises(mergesim.ScenarioError, match="empty list"):
        mergesim.parallel_env(agents=[])
    with pytest.raises(mergesim.ScenarioError, match="list of vehicle names"):
        mergesim.parallel_env(agents="ego")
    mixed = ", ".join(connected_planner_vehicles("mixed_traffic"))
    with pytest.raises(mergesim.ScenarioError, match=f"IDM.*not connected.*{mixed}"):
        mergesim.parallel_env("mixed_traffic", agents=["human_ahead"])
    not_connected = {"vehicles": [{**v, "connected": False} for v in _vehicles("urgent_merge")]}
    with pytest.raises(mergesim.ScenarioError, match="no connected, planner-driven vehicle"):
        mergesim.parallel_env(params=not_connected)


def test_step_needs_one_action_per_live_agent() -> None:
    env = mergesim.parallel_env(params=SHORT)
    with pytest.raises(mergesim.ScenarioError, match="reset"):
        env.step({"ego": MERGE, "obstacle": MERGE})
    env.reset(seed=0)
    with pytest.raises(mergesim.ScenarioError, match="missing: obstacle"):
        env.step({"ego": MERGE})
    with pytest.raises(mergesim.ScenarioError, match="not live: nobody"):
        env.step({"ego": MERGE, "obstacle": MERGE, "nobody": MERGE})
    with pytest.raises(mergesim.ScenarioError, match="finite"):
        env.step({"ego": [np.nan, 0.0], "obstacle": MERGE})


def rollout(seed: int, steps: int = 15) -> tuple:
    env = mergesim.parallel_env(params=SHORT)
    for i, agent in enumerate(env.possible_agents):
        env.action_space(agent).seed(100 + i)
    observations, _ = env.reset(seed=seed)
    trace: List[Dict[str, np.ndarray]] = [observations]
    rewards_trace = []
    for _ in range(steps):
        if not env.agents:
            break
        actions = {a: env.action_space(a).sample() for a in env.agents}
        observations, rewards, _, _, _ = env.step(actions)
        trace.append(observations)
        rewards_trace.append(rewards)
    return trace, rewards_trace


def test_same_seed_and_actions_same_episode_other_seed_other_instance() -> None:
    a, ra = rollout(seed=5)
    b, rb = rollout(seed=5)
    assert len(a) == len(b) > 1
    for oa, ob in zip(a, b):
        assert oa.keys() == ob.keys()
        for agent in oa:
            np.testing.assert_array_equal(oa[agent], ob[agent])
    assert ra == rb
    c, _ = rollout(seed=6)
    assert not np.array_equal(a[0]["ego"], c[0]["ego"])


def test_two_agents_driven_into_each_other_both_terminate() -> None:
    """The ego, fast in the through lane, runs into the obstacle, stopping there: both collide,
    both terminate, and each pays its own collision penalty and the team's."""
    env = mergesim.parallel_env(params={"sim": {"duration_s": 10.0}})
    env.reset(seed=1)
    actions = {"ego": np.array([30.0, 0.0]), "obstacle": np.array([0.0, 0.0])}
    for _ in range(100):
        _, rewards, terminations, truncations, infos = env.step(
            {a: actions[a] for a in env.agents}
        )
        if any(terminations.values()) or any(truncations.values()):
            break
    assert terminations == {"ego": True, "obstacle": True}, infos
    assert all(infos[a]["collision"] for a in ("ego", "obstacle"))
    own, team = env.reward_weights, env.team_weights
    mean_progress = np.mean([infos[a]["progress"] for a in ("ego", "obstacle")])
    for agent in ("ego", "obstacle"):
        assert infos[agent]["team_reward"] == pytest.approx(
            team.progress * mean_progress - team.collision
        )
        assert rewards[agent] == infos[agent]["own_reward"] + infos[agent]["team_reward"]
        assert rewards[agent] < -own.collision - team.collision + 1.0
    assert env.agents == []


def test_a_finished_agent_leaves_and_its_planner_drives_its_car_on() -> None:
    """The ego drives into the lower road edge and terminates; the obstacle stays an agent, and
    the ego's car, handed back to its planner, drives on: back to its lane's centre (its last
    command was the edge), then over the lane divider (it merges)."""
    env = mergesim.parallel_env(params={"sim": {"duration_s": 20.0}})
    env.reset(seed=3)
    low = env.action_space("ego").low[1]
    for _ in range(80):
        _, _, terminations, truncations, infos = env.step(
            {"ego": np.array([20.0, low]), "obstacle": MERGE}
        )
        if terminations["ego"] or truncations["ego"]:
            break
    assert terminations["ego"] and infos["ego"]["road_edge"], infos["ego"]
    assert not terminations["obstacle"] and not truncations["obstacle"]
    # The edge costs the ego its own penalty; the team term has no penalty in it.
    assert infos["ego"]["own_reward"] < -env.reward_weights.road_edge + 0.5
    mean_progress = np.mean([infos[a]["progress"] for a in ("ego", "obstacle")])
    for agent in ("ego", "obstacle"):
        assert infos[agent]["team_reward"] == pytest.approx(
            env.team_weights.progress * mean_progress
        )
    assert env.agents == ["obstacle"]
    left_at = env.vehicle_state("ego")
    lane_width_m, y_bottom_m = env.road["lane_width_m"], env.road["y_bottom_m"]
    lower_lane_centre_m = y_bottom_m + 0.5 * lane_width_m
    assert left_at["y_m"] < lower_lane_centre_m - 0.5
    trace = []
    for _ in range(120):
        observations, rewards, terminations, truncations, infos = env.step({"obstacle": MERGE})
        assert set(observations) == {"obstacle"}
        assert not infos["obstacle"]["collision"]
        # One live agent: the team's mean progress is its own.
        assert infos["obstacle"]["team_reward"] == pytest.approx(
            env.team_weights.progress * infos["obstacle"]["progress"]
        )
        trace.append(env.vehicle_state("ego"))
        if not env.agents:
            break
    assert len(trace) == 120
    assert trace[30]["y_m"] == pytest.approx(lower_lane_centre_m, abs=0.3)
    assert trace[-1]["y_m"] > y_bottom_m + lane_width_m  # over the divider
    assert trace[-1]["x_m"] > left_at["x_m"] + 150.0
    with pytest.raises(mergesim.ScenarioError, match="not one of"):
        env.vehicle_state("nobody")


def test_render_rgb_array() -> None:
    env = mergesim.parallel_env(params=SHORT, render_mode="rgb_array")
    env.reset(seed=0)
    image = env.render()
    assert image is not None and image.dtype == np.uint8 and image.shape[2] == 3


def test_the_example_runs(tmp_path: pathlib.Path) -> None:
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "60"],
        check=True,
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert "60 steps" in done.stdout and "steps/s" in done.stdout, done.stdout
