"""mergesim.MergeEnv: the Gymnasium contract, determinism, the episode's end, rendering."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mergesim

from conftest import SHORT

HOLD_LANE = np.array([20.0, -3.5], dtype=np.float32)


def rollout(env: mergesim.MergeEnv, seed: int, steps: int, action: np.ndarray = HOLD_LANE):
    obs, _ = env.reset(seed=seed)
    trace = [obs]
    rewards = []
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(action)
        trace.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            break
    return np.array(trace), np.array(rewards)


def test_check_env() -> None:
    env = mergesim.MergeEnv(params=SHORT, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)


def test_registered_with_gymnasium() -> None:
    env = gym.make("mergesim/Merge-v0", params=SHORT)
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    env.close()


def test_same_seed_same_episode_other_seed_other_instance() -> None:
    a, ra = rollout(mergesim.MergeEnv(params=SHORT), seed=5, steps=10)
    b, rb = rollout(mergesim.MergeEnv(params=SHORT), seed=5, steps=10)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(ra, rb)
    c, _ = rollout(mergesim.MergeEnv(params=SHORT), seed=6, steps=10)
    assert not np.array_equal(a, c)


def test_observation_layout_and_spaces() -> None:
    env = mergesim.MergeEnv(params=SHORT, neighbours=2)
    obs, info = env.reset(seed=1)
    assert obs.dtype == np.float32 and obs.shape == (len(env.observation_names()),) == (20,)
    names = env.observation_names()
    assert obs[names.index("lateral_offset_m")] == pytest.approx(-3.5, abs=0.3)
    assert obs[names.index("neighbour0.present")] == 1.0
    assert obs[names.index("neighbour1.present")] == 0.0
    assert info["instance_seed"] == 1
    assert env.action_space.shape == (2,)


def test_truncated_at_the_scenario_duration() -> None:
    env = mergesim.MergeEnv(params=SHORT)
    env.reset(seed=2)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(HOLD_LANE)
        steps += 1
        if terminated or truncated:
            break
    assert truncated and not terminated
    assert steps == 20 and info["time_s"] == pytest.approx(2.0)
    with pytest.raises(mergesim.ScenarioError):
        env.step(HOLD_LANE)


def test_road_edge_terminates_with_a_penalty() -> None:
    env = mergesim.MergeEnv(params={"sim": {"duration_s": 6.0}})
    env.reset(seed=3)
    # Hard towards the lower road edge (the lowest lateral position the action space allows).
    action = np.array([20.0, env.action_space.low[1]], dtype=np.float32)
    for _ in range(60):
        _, reward, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    assert terminated and info["road_edge"]
    assert reward < -5.0


def test_render_rgb_array() -> None:
    env = mergesim.MergeEnv(params=SHORT, render_mode="rgb_array")
    env.reset(seed=0)
    image = env.render()
    assert image is not None and image.dtype == np.uint8 and image.shape[2] == 3
    assert (image == (220, 40, 40)).all(axis=2).any()  # the agent
    assert (image == (50, 110, 220)).all(axis=2).any()  # the obstacle


def test_other_vehicle_and_planner() -> None:
    env = mergesim.MergeEnv(params=SHORT, vehicle="obstacle", planner="pf-cs")
    assert env.vehicle_names[env.agent] == "obstacle"
    obs, _ = env.reset(seed=0)
    assert obs[env.observation_names().index("lateral_offset_m")] == pytest.approx(0.0, abs=0.3)


def test_a_collision_costs_the_collision_penalty_not_its_jerk() -> None:
    """An impact's jerk is hundreds of m/s³: the comfort term is capped per step, so the
    collision penalty is what the step costs."""
    env = mergesim.MergeEnv()
    env.reset(seed=7)
    weights = env.reward_weights
    for _ in range(250):
        _, reward, terminated, truncated, info = env.step(np.array([30.0, 0.0], dtype=np.float32))
        if terminated or truncated:
            break
    assert terminated and info["collision"], info
    assert abs(info["jerk_mps3"]) > 100.0
    lowest = -weights.collision - weights.comfort_cap
    assert lowest <= reward < -weights.collision + 2.0 * weights.progress


def test_bad_reward_weights_and_step_before_reset() -> None:
    with pytest.raises(mergesim.ScenarioError, match="RewardWeights"):
        mergesim.MergeEnv(params=SHORT, reward_weights={"jerk": 0.0})  # type: ignore[arg-type]
    env = mergesim.MergeEnv(params=SHORT)
    with pytest.raises(mergesim.ScenarioError, match="before reset"):
        env.step(HOLD_LANE)


def test_a_road_of_lanes_is_refused_not_misread() -> None:
    # The environment's observations and commands are the straight merge road's.
    for name in ("curved_merge", "on_ramp"):
        refused = "straight \\[sim.road\\] merge road only"
        with pytest.raises(mergesim.ScenarioError, match=refused):
            mergesim.MergeEnv(scenario=name)


def test_a_commonroad_vehicle_model_steps_and_an_unknown_one_is_refused() -> None:
    rapier = mergesim.MergeEnv(params=SHORT, randomise=False)
    ks = mergesim.MergeEnv(params={"sim": {**SHORT["sim"], "vehicle_model": "ks"}}, randomise=False)
    rapier.reset(seed=0)
    ks.reset(seed=0)
    for _ in range(15):
        obs_r, _, _, _, _ = rapier.step(HOLD_LANE)
        obs_k, _, terminated, truncated, _ = ks.step(HOLD_LANE)
        assert not (terminated or truncated)
    assert np.all(np.isfinite(obs_k))
    assert not np.array_equal(obs_r, obs_k)  # another model moved the cars
    with pytest.raises(mergesim.ScenarioError, match="unknown vehicle model 'bicycle'"):
        mergesim.MergeEnv(params={"sim": {"vehicle_model": "bicycle"}})
