"""One agent's spaces, observation, reward terms and end: shared by ``MergeEnv`` (one agent) and
``MergeParallelEnv`` (several), so that an agent sees and earns the same in both
(python/README.md tabulates them)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Optional, Tuple

import numpy as np
from gymnasium import spaces

from ._native import ScenarioError
from .render import lower_edge_y_m

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
#: Margin before the road's end at which an agent's episode ends (m, plus two steps of travel).
ROAD_END_MARGIN_M = 1.0

# Columns of a state row (``EnvCore.state_columns()``).
X, Y, YAW, SPEED, VX, VY, YAW_RATE = range(7)


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


def through_lane_y_m(road: Mapping[str, float]) -> float:
    """The through (upper) lane's centre (m, the road's y): lateral offsets are from it."""
    return road["y_bottom_m"] + 1.5 * road["lane_width_m"]


def action_space(road: Mapping[str, float], nominal_target_speed_mps: float) -> spaces.Box:
    """[target_speed_mps, lateral_offset_m]: speed up to 1.5 × the nominal target speed, lateral
    position from the ending lane's lower edge's half lane beyond to the through lane's edge."""
    lane_width_m = road["lane_width_m"]
    max_speed_mps = 1.5 * float(nominal_target_speed_mps)
    return spaces.Box(
        low=np.array([0.0, -1.5 * lane_width_m], dtype=np.float32),
        high=np.array([max_speed_mps, 0.5 * lane_width_m], dtype=np.float32),
        dtype=np.float32,
    )


def observation_space(neighbours: int) -> spaces.Box:
    """The observation: ``EGO_FIELDS`` then ``NEIGHBOUR_FIELDS`` for each of ``neighbours``."""
    size = len(EGO_FIELDS) + len(NEIGHBOUR_FIELDS) * neighbours
    return spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float32)


def observation_names(neighbours: int) -> Tuple[str, ...]:
    """The name of every observation entry, in order."""
    names = list(EGO_FIELDS)
    for k in range(neighbours):
        names += [f"neighbour{k}.{f}" for f in NEIGHBOUR_FIELDS]
    return tuple(names)


def checked_action(action: object, space: spaces.Box) -> np.ndarray:
    """``action`` as [target_speed_mps, lateral_offset_m] (float64), clipped to ``space``.

    Raises:
        ScenarioError: Not finite.
    """
    a = np.clip(np.asarray(action, dtype=np.float64).reshape(2), space.low, space.high)
    if not np.all(np.isfinite(a)):
        raise ScenarioError(f"action {action!r}: must be finite")
    return a


def observe(
    states: np.ndarray,
    agent: int,
    road: Mapping[str, float],
    target_speed_mps: float,
    accel_mps2: float,
    neighbours: int,
) -> np.ndarray:
    """Vehicle ``agent``'s observation (``observation_names``) from every vehicle's state row."""
    me = states[agent]
    ego = [
        me[SPEED],
        target_speed_mps,
        me[Y] - through_lane_y_m(road),
        me[YAW],
        me[YAW_RATE],
        accel_mps2,
        road["merge_end_x_m"] - me[X],
        road["end_x_m"] - me[X],
        road["y_bottom_m"] + 2.0 * road["lane_width_m"] - me[Y],
        me[Y] - float(lower_edge_y_m(road, np.array(me[X]))),
    ]
    others = np.delete(states, agent, axis=0)
    rel = np.zeros((neighbours, len(NEIGHBOUR_FIELDS)))
    if len(others):
        dx = others[:, X] - me[X]
        dy = others[:, Y] - me[Y]
        distance = np.hypot(dx, dy)
        # Nearest first; ties by id order (a stable sort), so the order is deterministic.
        nearest = np.argsort(distance, kind="stable")
        order = [i for i in nearest if distance[i] <= PERCEPTION_RANGE_M]
        for row, i in enumerate(order[:neighbours]):
            rel[row] = (1.0, dx[i], dy[i], others[i, VX] - me[VX], others[i, VY] - me[VY])
    return np.concatenate([np.asarray(ego), rel.ravel()]).astype(np.float32)


@dataclass(frozen=True)
class StepTerms:
    """What one step did to one agent's vehicle (its reward terms, unweighted except comfort).

    Attributes:
        progress: Distance travelled over the distance at the target speed in one period.
        accel_mps2: Mean longitudinal acceleration over the step (change of speed / period).
        jerk_mps3: Change of ``accel_mps2`` from the step before / period.
        comfort: The weighted, capped comfort penalty (≥ 0).
    """

    progress: float
    accel_mps2: float
    jerk_mps3: float
    comfort: float


def step_terms(
    before: np.ndarray,
    after: np.ndarray,
    accel_before_mps2: float,
    target_speed_mps: float,
    period_s: float,
    weights: RewardWeights,
) -> StepTerms:
    """The terms of one step of a vehicle, from its state rows before and after it."""
    target_mps = max(float(target_speed_mps), 0.1)
    progress = (after[X] - before[X]) / (target_mps * period_s)
    accel_mps2 = (after[SPEED] - before[SPEED]) / period_s
    jerk_mps3 = (accel_mps2 - accel_before_mps2) / period_s
    comfort = min(
        weights.jerk * jerk_mps3**2 + weights.yaw_rate * after[YAW_RATE] ** 2,
        weights.comfort_cap,
    )
    return StepTerms(float(progress), float(accel_mps2), float(jerk_mps3), float(comfort))


def own_reward(
    terms: StepTerms, hit_vehicle: bool, hit_edge: bool, weights: RewardWeights
) -> float:
    """``MergeEnv``'s reward of one step: progress − comfort − collision − road edge."""
    return float(
        weights.progress * terms.progress
        - terms.comfort
        - (weights.collision if hit_vehicle else 0.0)
        - (weights.road_edge if hit_edge else 0.0)
    )


def end_reached(
    me: np.ndarray,
    length_m: float,
    road: Mapping[str, float],
    period_s: float,
    name: str,
    road_end: Optional[str],
) -> bool:
    """Whether vehicle ``name`` (state row ``me``) has reached the road's end: the simulation
    says so, or its front is within ``ROAD_END_MARGIN_M`` plus two steps of travel of it."""
    front_m = me[X] + 0.5 * length_m
    end_margin_m = ROAD_END_MARGIN_M + 2.0 * me[SPEED] * period_s
    return bool(road_end == name or front_m >= road["end_x_m"] - end_margin_m)
