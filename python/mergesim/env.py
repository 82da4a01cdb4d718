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

from dataclasses import dataclass
from typing import Any, Dict, Mapping, Optional, Tuple

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _native
from ._common import ScenarioSource, count_arg, params_json, scenario_arg, seed_arg
from .render import lower_edge_y_m, top_down

#: Names of the agent's own observation entries (then 5 per neighbour: ``NEIGHBOUR_FIELDS``).
EGO_FIELDS = (
    "speed_mps",
    "target_speed_mps",
    "lateral_offset_m",
    "yaw_rad",
    "yaw_rate_radps",
    "accel_long_mps2",
    "to_merge_end_m",
    "to_road_end_m",
    "to_upper_edge_m",
    "to_lower_edge_m",
)
#: Per neighbour, nearest first: present (1/0), its position and velocity relative to the agent.
NEIGHBOUR_FIELDS = ("present", "dx_m", "dy_m", "dvx_mps", "dvy_mps")

#: Neighbours farther than this are not observed (the planners' perception range, m).
PERCEPTION_RANGE_M = 250.0
#: Margin before the road's end at which the episode ends (m, plus two steps of travel).
ROAD_END_MARGIN_M = 1.0

_X, _Y, _YAW, _SPEED, _VX, _VY, _YAW_RATE = range(7)


@dataclass(frozen=True)
class RewardWeights:
    """Weights of the reward terms (python/README.md, "Reward").

    Attributes:
        progress: Per step, times the distance travelled over the distance at the target speed.
        jerk: Times the squared longitudinal jerk (m/s³)²: the change over the step of the mean
            acceleration over the step (the change of speed / period).
        yaw_rate: Times the squared yaw rate (rad/s)².
        comfort_cap: Largest comfort penalty (jerk + yaw-rate terms) of one step: an impact's
            jerk (hundreds of m/s³) must not outweigh the collision penalty itself.
        collision: Subtracted when the agent collides with another vehicle (ends the episode).
        road_edge: Subtracted when the agent touches a road edge (ends the episode).
    """

    progress: float = 0.1
    jerk: float = 0.001
    yaw_rate: float = 0.5
    comfort_cap: float = 1.0
    collision: float = 10.0
    road_edge: float = 10.0


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
        lane_width_m = self.road["lane_width_m"]
        max_speed_mps = 1.5 * float(self._core.nominal_target_speed_mps)
        self.action_space: spaces.Box = spaces.Box(
            low=np.array([0.0, -1.5 * lane_width_m], dtype=np.float32),
            high=np.array([max_speed_mps, 0.5 * lane_width_m], dtype=np.float32),
            dtype=np.float32,
        )
        size = len(EGO_FIELDS) + len(NEIGHBOUR_FIELDS) * self._k
        self.observation_space: spaces.Box = spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float32)
        self._states = np.zeros((len(self.vehicle_names), 9))
        # Mean longitudinal acceleration over the last step (m/s²): the change of speed over the
        # period, steadier than the physics step's own.
        self._accel_mps2 = 0.0
        self._time_s = 0.0
        self._over = True

    # --- geometry -------------------------------------------------------------------------

    def _through_lane_y_m(self) -> float:
        return self.road["y_bottom_m"] + 1.5 * self.road["lane_width_m"]

    def observation_names(self) -> Tuple[str, ...]:
        """The name of every observation entry, in order."""
        names = list(EGO_FIELDS)
        for k in range(self._k):
            names += [f"neighbour{k}.{f}" for f in NEIGHBOUR_FIELDS]
        return tuple(names)

    def _observe(self) -> np.ndarray:
        s = self._states
        me = s[self.agent]
        road = self.road
        ego = [
            me[_SPEED],
            self._core.agent_target_speed_mps,
            me[_Y] - self._through_lane_y_m(),
            me[_YAW],
            me[_YAW_RATE],
            self._accel_mps2,
            road["merge_end_x_m"] - me[_X],
            road["end_x_m"] - me[_X],
            road["y_bottom_m"] + 2.0 * road["lane_width_m"] - me[_Y],
            me[_Y] - float(lower_edge_y_m(road, np.array(me[_X]))),
        ]
        others = np.delete(s, self.agent, axis=0)
        rel = np.zeros((self._k, len(NEIGHBOUR_FIELDS)))
        if len(others):
            dx = others[:, _X] - me[_X]
            dy = others[:, _Y] - me[_Y]
            distance = np.hypot(dx, dy)
            # Nearest first; ties by id order (a stable sort), so the order is deterministic.
            nearest = np.argsort(distance, kind="stable")
            order = [i for i in nearest if distance[i] <= PERCEPTION_RANGE_M]
            for row, i in enumerate(order[: self._k]):
                rel[row] = (
                    1.0,
                    dx[i],
                    dy[i],
                    others[i, _VX] - me[_VX],
                    others[i, _VY] - me[_VY],
                )
        return np.concatenate([np.asarray(ego), rel.ravel()]).astype(np.float32)

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
        a = np.clip(
            np.asarray(action, dtype=np.float64).reshape(2),
            self.action_space.low,
            self.action_space.high,
        )
        if not np.all(np.isfinite(a)):
            raise _native.ScenarioError(f"action {action!r}: must be finite")
        x_before = self._states[self.agent, _X]
        speed_before_mps = self._states[self.agent, _SPEED]
        states, hit_vehicle, hit_edge, road_end, error, time_s = self._core.step(
            float(a[0]), float(a[1]) + self._through_lane_y_m()
        )
        self._states = np.asarray(states, dtype=np.float64)
        self._time_s = float(time_s)
        me = self._states[self.agent]
        w = self.reward_weights
        target_mps = max(float(self._core.agent_target_speed_mps), 0.1)
        progress = (me[_X] - x_before) / (target_mps * self.period_s)
        accel_mps2 = (me[_SPEED] - speed_before_mps) / self.period_s
        jerk_mps3 = (accel_mps2 - self._accel_mps2) / self.period_s
        self._accel_mps2 = float(accel_mps2)
        comfort = min(w.jerk * jerk_mps3**2 + w.yaw_rate * me[_YAW_RATE] ** 2, w.comfort_cap)
        reward = (
            w.progress * progress
            - comfort
            - (w.collision if hit_vehicle else 0.0)
            - (w.road_edge if hit_edge else 0.0)
        )
        length_m = self._sizes_m[self.agent][0]
        front_m = me[_X] + 0.5 * length_m
        end_margin_m = ROAD_END_MARGIN_M + 2.0 * me[_SPEED] * self.period_s
        end_reached = bool(
            road_end == self.vehicle_names[self.agent]
            or front_m >= self.road["end_x_m"] - end_margin_m
        )
        terminated = bool(hit_vehicle or hit_edge or end_reached or error is not None)
        truncated = bool(
            not terminated
            and (road_end is not None or self._time_s >= self._core.duration_s - 1e-9)
        )
        self._over = terminated or truncated
        info: Dict[str, Any] = {
            "time_s": self._time_s,
            "x_m": float(me[_X]),
            "collision": bool(hit_vehicle),
            "road_edge": bool(hit_edge),
            "end_of_road": bool(end_reached),
            "jerk_mps3": float(jerk_mps3),
        }
        if road_end is not None and not end_reached:
            info["other_reached_road_end"] = road_end
        if error is not None:
            info["error"] = error
        return self._observe(), float(reward), terminated, truncated, info

    def render(self) -> Optional[np.ndarray]:  # type: ignore[override]
        """A top-down RGB picture around the agent (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        return top_down(self.road, self._states, self._sizes_m, self.agent)
