"""``mergesim.MergeEnv``: a Gymnasium environment in which the agent drives one vehicle of a
merge scenario while the others run the scenario's planners.

One step is one planning period (``[sim] planner_period_s``, 0.1 s = 10 Hz in the built-ins):
the action is held for that long while the world advances its physics steps (2 ms each). The
action does not steer or brake directly: it becomes a path (straight ahead at the commanded
speed, blending smoothly to the commanded lateral position over max(20 m, 1.5 s) of travel)
that the simulator's own pure-pursuit / PID tracker follows, exactly as it follows a planner's
path. The agent's path is broadcast like a planner's, so connected PF-ISO vehicles take it into
account. python/README.md tabulates the spaces, the reward and the episode's end.
"""

from __future__ import annotations

from typing import Any, Dict, Mapping, Optional, Tuple

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _native
from ._agent import (
    EGO_FIELDS,
    NEIGHBOUR_FIELDS,
    PERCEPTION_RANGE_M,
    ROAD_END_MARGIN_M,
    X,
    RewardWeights,
    action_space,
    checked_action,
    end_reached,
    observation_names,
    observation_space,
    observe,
    own_reward,
    step_terms,
    through_lane_y_m,
)
from ._common import ScenarioSource, count_arg, params_json, scenario_arg, seed_arg
from .render import top_down

__all__ = [
    "EGO_FIELDS",
    "NEIGHBOUR_FIELDS",
    "PERCEPTION_RANGE_M",
    "ROAD_END_MARGIN_M",
    "MergeEnv",
    "RewardWeights",
]


class MergeEnv(gym.Env):
    """The agent drives one vehicle of a scenario (module doc and python/README.md).

    Args:
        scenario: A built-in name, a path or TOML text (as in :func:`mergesim.run`).
        vehicle: The agent's vehicle by name (None: ``ego``, or the first vehicle).
        planner: Planner of the other planner-driven vehicles (None: the scenario's).
        params: Overrides merged over the scenario (as in :func:`mergesim.run`).
        neighbours: How many nearest vehicles the observation holds (K).
        randomise: Whether ``reset`` draws a randomised instance (``Scenario::instantiate``);
            False: always the nominal scenario.
        reward_weights: The reward's weights.
        render_mode: None or ``"rgb_array"`` (a top-down picture around the agent).

    Raises:
        ScenarioError: Bad input (with ``merge_sim``'s message).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        scenario: ScenarioSource = "urgent_merge",
        vehicle: Optional[str] = None,
        planner: Optional[str] = None,
        params: Optional[Mapping[str, Any]] = None,
        neighbours: int = 4,
        randomise: bool = True,
        reward_weights: RewardWeights = RewardWeights(),
        render_mode: Optional[str] = None,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise _native.ScenarioError(
                f"render_mode {render_mode!r}: not one of {self.metadata['render_modes']}"
            )
        self._core = _native.EnvCore(scenario_arg(scenario), params_json(params), planner, vehicle)
        self._k = count_arg("neighbours", neighbours)
        self._randomise = bool(randomise)
        if not isinstance(reward_weights, RewardWeights):
            raise _native.ScenarioError(
                "reward_weights: must be a mergesim.RewardWeights, e.g. RewardWeights(jerk=0.0),"
                f" got {type(reward_weights).__name__}"
            )
        self.reward_weights = reward_weights
        self.render_mode = render_mode
        self.agent = self._core.agent_index
        self.vehicle_names = list(self._core.vehicle_names)
        self._sizes_m = list(self._core.vehicle_sizes_m)
        self.road: Dict[str, float] = dict(self._core.road)
        self.period_s = float(self._core.planner_period_s)
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.period_s)}
        self.action_space: spaces.Box = action_space(
            self.road, float(self._core.nominal_target_speed_mps)
        )
        self.observation_space: spaces.Box = observation_space(self._k)
        self._states = np.zeros((len(self.vehicle_names), 9))
        # Mean longitudinal acceleration over the last step (m/s²): the change of speed over the
        # period, steadier than the physics step's own.
        self._accel_mps2 = 0.0
        self._time_s = 0.0
        self._over = True

    # --- observation ---------------------------------------------------------------------

    def observation_names(self) -> Tuple[str, ...]:
        """The name of every observation entry, in order."""
        return observation_names(self._k)

    def _observe(self) -> np.ndarray:
        return observe(
            self._states,
            self.agent,
            self.road,
            float(self._core.agent_target_speed_mps),
            self._accel_mps2,
            self._k,
        )

    # --- Gymnasium API ---------------------------------------------------------------------

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        """Starts an episode.

        ``reset(seed=s)`` runs the instance ``merge_sim run --seed s`` runs (the others behave
        exactly as there until the agent does something different); without a seed, the
        instance seed is drawn from the environment's generator (seeded by the last seed).
        """
        super().reset(seed=seed)
        if not self._randomise:
            instance_seed = None
        elif seed is not None:
            instance_seed = seed_arg("seed", seed)
        else:
            instance_seed = int(self.np_random.integers(0, 2**63))
        self._states = np.asarray(self._core.reset(instance_seed), dtype=np.float64)
        self.road = dict(self._core.road)
        self._accel_mps2 = 0.0
        self._time_s = 0.0
        self._over = False
        info = {"time_s": 0.0, "instance_seed": instance_seed}
        return self._observe(), info

    def step(
        self, action: np.ndarray
    ) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        """Holds ``action`` = [target_speed_mps, lateral_offset_m] for one planning period.

        The action is clipped to the action space; ``lateral_offset_m`` is the commanded lateral
        position relative to the through (upper) lane's centre (0: merged; −lane width: the
        centre of the ending lane).
        """
        if self._over:
            raise _native.ScenarioError(
                "step before reset() or after the episode ended: call reset() first"
            )
        a = checked_action(action, self.action_space)
        before = self._states[self.agent].copy()
        states, hit_vehicle, hit_edge, road_end, error, time_s = self._core.step(
            float(a[0]), float(a[1]) + through_lane_y_m(self.road)
        )
        self._states = np.asarray(states, dtype=np.float64)
        self._time_s = float(time_s)
        me = self._states[self.agent]
        terms = step_terms(
            before,
            me,
            self._accel_mps2,
            float(self._core.agent_target_speed_mps),
            self.period_s,
            self.reward_weights,
        )
        self._accel_mps2 = terms.accel_mps2
        jerk_mps3 = terms.jerk_mps3
        reward = own_reward(terms, bool(hit_vehicle), bool(hit_edge), self.reward_weights)
        end_reached_now = end_reached(
            me,
            self._sizes_m[self.agent][0],
            self.road,
            self.period_s,
            self.vehicle_names[self.agent],
            road_end,
        )
        terminated = bool(hit_vehicle or hit_edge or end_reached_now or error is not None)
        truncated = bool(
            not terminated
            and (road_end is not None or self._time_s >= self._core.duration_s - 1e-9)
        )
        self._over = terminated or truncated
        info: Dict[str, Any] = {
            "time_s": self._time_s,
            "x_m": float(me[X]),
            "collision": bool(hit_vehicle),
            "road_edge": bool(hit_edge),
            "end_of_road": bool(end_reached_now),
            "jerk_mps3": float(jerk_mps3),
        }
        if road_end is not None and not end_reached_now:
            info["other_reached_road_end"] = road_end
        if error is not None:
            info["error"] = error
        return self._observe(), float(reward), terminated, truncated, info

    def render(self) -> Optional[np.ndarray]:  # type: ignore[override]
        """A top-down RGB picture around the agent (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        return top_down(self.road, self._states, self._sizes_m, self.agent)
