"""``mergesim.parallel_env``: a PettingZoo ``ParallelEnv`` in which several connected vehicles of
a merge scenario are agents at once, while the other vehicles run the scenario's drivers. (The
module is ``mergesim.parallel``: one named ``parallel_env`` would be hidden by the function.)

Each agent sees, does and earns what ``MergeEnv``'s agent does (the same observation, action
and reward terms, from ``mergesim._agent``), plus a shared team term (``TeamRewardWeights``).
All agents act at once, one planning period per step. An agent that collides, touches a road
edge or reaches the road's end terminates and leaves ``agents``; its vehicle is handed back to
its own planner (the scenario's, or ``planner``), which drives it to the end of the episode.
python/README.md ("Several agents") documents the reward exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from pettingzoo import ParallelEnv

from . import _native
from ._agent import (
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

__all__ = ["MergeParallelEnv", "TeamRewardWeights", "parallel_env"]


@dataclass(frozen=True)
class TeamRewardWeights:
    """Weights of the shared team term every live agent gets (python/README.md, "Several
    agents").

    Attributes:
        progress: Times the mean, over the agents live at the step's start, of their progress
            (distance travelled over the distance at their target speed in one period).
        collision: Subtracted from every agent live at the step's start when any of them
            collided with a vehicle during the step.
    """

    progress: float = 0.1
    collision: float = 10.0


class MergeParallelEnv(ParallelEnv):  # type: ignore[misc]
    """Several vehicles of a scenario are agents at once (module doc and python/README.md).

    Args:
        scenario: A built-in name, a path or TOML text (as in :func:`mergesim.run`).
        agents: The agents' vehicles by name, each connected and planner-driven; None: every
            connected, planner-driven vehicle (not IDM, lane-keeping or prescribed-speed ones).
        planner: Planner of the other planner-driven vehicles and of the finished agents'
            vehicles (None: each vehicle's own).
        params: Overrides merged over the scenario (as in :func:`mergesim.run`).
        neighbours: How many nearest vehicles each observation holds (K).
        randomise: Whether ``reset`` draws a randomised instance; False: always the nominal one.
        reward_weights: The weights of each agent's own terms (``MergeEnv``'s reward).
        team_weights: The weights of the shared team term.
        render_mode: None or ``"rgb_array"`` (a top-down picture around the first live agent).

    Raises:
        ScenarioError: Bad input; an unknown agent name names the valid ones.
    """

    metadata = {
        "name": "mergesim_merge_v0",
        "render_modes": ["rgb_array"],
        "render_fps": 10,
        "is_parallelizable": True,
    }

    def __init__(
        self,
        scenario: ScenarioSource = "urgent_merge",
        agents: Optional[Sequence[str]] = None,
        planner: Optional[str] = None,
        params: Optional[Mapping[str, Any]] = None,
        neighbours: int = 4,
        randomise: bool = True,
        reward_weights: RewardWeights = RewardWeights(),
        team_weights: TeamRewardWeights = TeamRewardWeights(),
        render_mode: Optional[str] = None,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise _native.ScenarioError(
                f"render_mode {render_mode!r}: not one of {self.metadata['render_modes']}"
            )
        if not isinstance(reward_weights, RewardWeights):
            raise _native.ScenarioError(
                "reward_weights: must be a mergesim.RewardWeights, e.g. RewardWeights(jerk=0.0),"
                f" got {type(reward_weights).__name__}"
            )
        if not isinstance(team_weights, TeamRewardWeights):
            raise _native.ScenarioError(
                "team_weights: must be a mergesim.TeamRewardWeights, e.g."
                f" TeamRewardWeights(collision=0.0), got {type(team_weights).__name__}"
            )
        source, overrides = scenario_arg(scenario), params_json(params)
        if agents is None:
            self._core = _native.EnvCore(source, overrides, planner, connected_agents=True)
        else:
            self._core = _native.EnvCore(source, overrides, planner, agents=_names_arg(agents))
        self._k = count_arg("neighbours", neighbours)
        self._randomise = bool(randomise)
        self.reward_weights = reward_weights
        self.team_weights = team_weights
        self.render_mode = render_mode
        self.vehicle_names: List[str] = list(self._core.vehicle_names)
        self._sizes_m = list(self._core.vehicle_sizes_m)
        #: The agents' vehicle indices (rows of the state), by agent name.
        self._vehicle: Dict[str, int] = {
            self.vehicle_names[i]: i for i in self._core.agent_indices
        }
        self.possible_agents: List[str] = list(self._vehicle)
        self.agents: List[str] = []
        self.road: Dict[str, float] = dict(self._core.road)
        self.period_s = float(self._core.planner_period_s)
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.period_s)}
        nominal_mps = list(self._core.nominal_target_speeds_mps)
        self.action_spaces: Dict[str, spaces.Box] = {
            a: action_space(self.road, v) for a, v in zip(self.possible_agents, nominal_mps)
        }
        self.observation_spaces: Dict[str, spaces.Box] = {
            a: observation_space(self._k) for a in self.possible_agents
        }
        self._np_random, _ = seeding.np_random(None)
        self._states = np.zeros((len(self.vehicle_names), 9))
        self._accel_mps2: Dict[str, float] = {}
        self._target_mps: Dict[str, float] = {}
        self._time_s = 0.0

    # --- spaces -----------------------------------------------------------------------------

    def observation_space(self, agent: str) -> spaces.Box:
        """Agent ``agent``'s observation space (the same object at every call)."""
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        """Agent ``agent``'s action space (the same object at every call)."""
        return self.action_spaces[agent]

    def observation_names(self) -> Tuple[str, ...]:
        """The name of every observation entry, in order (as ``MergeEnv.observation_names``)."""
        return observation_names(self._k)

    def _observe(self, agent: str) -> np.ndarray:
        return observe(
            self._states,
            self._vehicle[agent],
            self.road,
            self._target_mps[agent],
            self._accel_mps2[agent],
            self._k,
        )

    # --- PettingZoo API ---------------------------------------------------------------------

    def reset(
        self, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[Dict[str, np.ndarray], Dict[str, Dict[str, Any]]]:
        """Starts an episode with every possible agent live.

        ``reset(seed=s)`` runs the instance ``merge_sim run --seed s`` runs; without a seed the
        instance seed is drawn from the environment's generator (seeded by the last seed).
        ``options`` is not used.
        """
        if seed is not None:
            self._np_random, _ = seeding.np_random(seed_arg("seed", seed))
        if not self._randomise:
            instance_seed = None
        elif seed is not None:
            instance_seed = seed_arg("seed", seed)
        else:
            instance_seed = int(self._np_random.integers(0, 2**63))
        self._states = np.asarray(self._core.reset(instance_seed), dtype=np.float64)
        self.road = dict(self._core.road)
        self._time_s = 0.0
        self.agents = list(self.possible_agents)
        targets_mps = list(self._core.agent_target_speeds_mps)
        self._target_mps = dict(zip(self.possible_agents, map(float, targets_mps)))
        self._accel_mps2 = {a: 0.0 for a in self.possible_agents}
        observations = {a: self._observe(a) for a in self.agents}
        infos = {a: {"time_s": 0.0, "instance_seed": instance_seed} for a in self.agents}
        return observations, infos

    def step(self, actions: Mapping[str, Any]) -> Tuple[
        Dict[str, np.ndarray],
        Dict[str, float],
        Dict[str, bool],
        Dict[str, bool],
        Dict[str, Dict[str, Any]],
    ]:
        """Holds each live agent's action = [target_speed_mps, lateral_offset_m] for one
        planning period (clipped to its action space, as in ``MergeEnv``); every live agent
        needs one. Returns (observations, rewards, terminations, truncations, infos), each keyed
        by the agents live before the step."""
        if not self.agents:
            raise _native.ScenarioError(
                "step with no live agent (before reset() or after the episode ended): call"
                " reset() first"
            )
        unknown = sorted(set(actions) - set(self.agents))
        missing = [a for a in self.agents if a not in actions]
        if unknown or missing:
            raise _native.ScenarioError(
                f"actions: one per live agent ({', '.join(self.agents)});"
                + (f" not live: {', '.join(map(str, unknown))};" if unknown else "")
                + (f" missing: {', '.join(missing)}" if missing else "")
            )
        live = list(self.agents)
        lane_y_m = through_lane_y_m(self.road)
        commands = []
        for agent in self.possible_agents:
            if agent in actions:
                a = checked_action(actions[agent], self.action_spaces[agent])
                commands.append((float(a[0]), float(a[1]) + lane_y_m))
            else:
                commands.append((0.0, lane_y_m))  # a finished agent's: ignored (handed back)
        before = self._states.copy()
        states, hit_vehicle, hit_edge, road_end, error, time_s = self._core.step_agents(commands)
        self._states = np.asarray(states, dtype=np.float64)
        self._time_s = float(time_s)
        slot = {a: i for i, a in enumerate(self.possible_agents)}
        terms = {}
        for agent in live:
            row = self._vehicle[agent]
            terms[agent] = step_terms(
                before[row],
                self._states[row],
                self._accel_mps2[agent],
                self._target_mps[agent],
                self.period_s,
                self.reward_weights,
            )
            self._accel_mps2[agent] = terms[agent].accel_mps2
        any_collision = any(hit_vehicle[slot[a]] for a in live)
        team_reward = float(
            self.team_weights.progress * np.mean([terms[a].progress for a in live])
            - (self.team_weights.collision if any_collision else 0.0)
        )
        timed_out = road_end is not None or self._time_s >= self._core.duration_s - 1e-9
        observations, rewards, terminations, truncations, infos = {}, {}, {}, {}, {}
        for agent in live:
            i, row = slot[agent], self._vehicle[agent]
            me = self._states[row]
            collided, edge = bool(hit_vehicle[i]), bool(hit_edge[i])
            own = own_reward(terms[agent], collided, edge, self.reward_weights)
            at_end = end_reached(
                me, self._sizes_m[row][0], self.road, self.period_s, agent, road_end
            )
            terminated = bool(collided or edge or at_end or error is not None)
            terminations[agent] = terminated
            truncations[agent] = bool(not terminated and timed_out)
            rewards[agent] = own + team_reward
            observations[agent] = self._observe(agent)
            info: Dict[str, Any] = {
                "time_s": self._time_s,
                "x_m": float(me[X]),
                "collision": collided,
                "road_edge": edge,
                "end_of_road": at_end,
                "jerk_mps3": terms[agent].jerk_mps3,
                "progress": terms[agent].progress,
                "own_reward": own,
                "team_reward": team_reward,
            }
            if road_end is not None and not at_end:
                info["other_reached_road_end"] = road_end
            if error is not None:
                info["error"] = error
            infos[agent] = info
            if terminated and error is None and road_end is None:
                # Its planner drives the vehicle from now on (the world goes on for the others).
                self._core.hand_back(i)
        self.agents = [a for a in live if not (terminations[a] or truncations[a])]
        return observations, rewards, terminations, truncations, infos

    def vehicle_state(self, vehicle: str) -> Dict[str, float]:
        """Vehicle ``vehicle``'s state now (any vehicle, by name; the columns of
        ``EnvCore.state_columns()``: x_m, y_m, yaw_rad, speed_mps, ...)."""
        if vehicle not in self.vehicle_names:
            raise _native.ScenarioError(
                f"vehicle {vehicle!r}: not one of {', '.join(self.vehicle_names)}"
            )
        row = self._states[self.vehicle_names.index(vehicle)]
        return {c: float(v) for c, v in zip(_native.EnvCore.state_columns(), row)}

    def render(self) -> Optional[np.ndarray]:
        """A top-down RGB picture around the first live agent (else the first agent), for
        ``render_mode="rgb_array"``; None otherwise."""
        if self.render_mode != "rgb_array":
            return None
        centre = (self.agents or self.possible_agents)[0]
        return top_down(self.road, self._states, self._sizes_m, self._vehicle[centre])

    def close(self) -> None:
        """Nothing to release (the simulation goes with the object)."""


def _names_arg(agents: object) -> List[str]:
    """``agents`` as a list of vehicle names (a single string is refused, not split)."""
    if isinstance(agents, (str, bytes)) or not isinstance(agents, Sequence):
        raise _native.ScenarioError(
            f"agents: a list of vehicle names, e.g. ['ego'], or None; got {agents!r}"
        )
    names = list(agents)
    bad = [n for n in names if not isinstance(n, str)]
    if bad:
        raise _native.ScenarioError(f"agents: vehicle names are strings; got {bad[0]!r}")
    return names


def parallel_env(
    scenario: ScenarioSource = "urgent_merge",
    agents: Optional[Sequence[str]] = None,
    planner: Optional[str] = None,
    params: Optional[Mapping[str, Any]] = None,
    neighbours: int = 4,
    randomise: bool = True,
    reward_weights: RewardWeights = RewardWeights(),
    team_weights: TeamRewardWeights = TeamRewardWeights(),
    render_mode: Optional[str] = None,
) -> MergeParallelEnv:
    """The multi-agent environment (:class:`MergeParallelEnv`, same arguments)."""
    return MergeParallelEnv(
        scenario=scenario,
        agents=agents,
        planner=planner,
        params=params,
        neighbours=neighbours,
        randomise=randomise,
        reward_weights=reward_weights,
        team_weights=team_weights,
        render_mode=render_mode,
    )
