"""Type stubs of the native module (Rust, PyO3). Use the wrappers in ``mergesim`` instead."""

from typing import Any, Callable, List, Optional, Sequence, Tuple

class ScenarioError(ValueError):
    """Bad input: what ``merge_sim`` rejects with exit code 2 (the message is the CLI's)."""

class SimulationError(RuntimeError):
    """The simulation failed while running (``merge_sim``'s exit code 1)."""

def run(
    scenario: str,
    params_json: Optional[str] = None,
    planner: Optional[str] = None,
    seed: Optional[int] = None,
) -> Tuple[str, str]:
    """One run: (the JSON summary, the time series as CSV text)."""

def sweep(
    scenario: str,
    planners: Sequence[str],
    runs: int,
    seed: int,
    params_json: Optional[str] = None,
    threads: Optional[int] = None,
) -> List[str]:
    """The JSONL rows of a paired sweep of the planners (none: the scenario's own)."""

def instance_seed(sweep_seed: int, instance: int) -> int:
    """The seed of instance ``instance`` of a sweep with seed ``sweep_seed``."""

def parse_seed(text: str) -> int:
    """A seed written as text (``"0x..."`` or decimal digits); raises ScenarioError otherwise."""

def study(
    plan: str,
    out: Optional[str] = None,
    threads: Optional[int] = None,
) -> str:
    """The report (``report.json``) of the study plan at ``plan``, as JSON text."""

def builtin_scenarios() -> List[str]:
    """Names of the built-in scenarios."""

def planners() -> List[str]:
    """Names of the registered planners (the built-in ones and the Python ones), sorted."""

def register_planner(name: str, factory: Callable[[], Any]) -> None:
    """Registers a Python planner factory under ``name``; ScenarioError for a bad or taken name."""

def unregister_planner(name: str) -> None:
    """Removes the Python planner ``name``; ScenarioError if there is none."""

def python_planners() -> List[str]:
    """Names of the registered Python planners, sorted."""

class Road:
    """The road of a run as lanes (``observation["road"]`` of a Python planner). s: arc length
    along a lane's centreline (m); d: lateral offset from it (m, positive to the left)."""

    def lane_ids(self) -> List[int]: ...
    def nearest_lane(self, x_m: float, y_m: float) -> Tuple[int, float, float]:
        """(lane id, s_m, d_m) of the point in its nearest lane."""
    def project(self, lane: int, x_m: float, y_m: float) -> Tuple[float, float]:
        """(s_m, d_m) of the point in lane ``lane``'s frame."""
    def point(self, lane: int, s_m: float, d_m: float = 0.0) -> Tuple[float, float]:
        """(x_m, y_m) at (s_m, d_m) of lane ``lane``'s frame."""
    def centreline(
        self, lane: int, s_from_m: float, s_to_m: float, step_m: float, d_m: float = 0.0
    ) -> List[Tuple[float, float]]:
        """Points of lane ``lane`` at offset ``d_m``, every ``step_m`` from ``s_from_m`` to ``s_to_m``."""
    def heading_rad(self, lane: int, s_m: float) -> float: ...
    def width_m(self, lane: int, s_m: float) -> float: ...
    def length_m(self, lane: int) -> float: ...
    def neighbours(self, lane: int) -> Tuple[Optional[int], Optional[int]]:
        """(left lane id or None, right lane id or None)."""
    def successors(self, lane: int) -> List[int]: ...
    def distance_to_closed_end_m(self, lane: int, s_m: float) -> Optional[float]:
        """How far ahead the lane must be left (every way on ends closed); None if it goes on."""

StepResult = Tuple[List[List[float]], bool, bool, Optional[str], Optional[str], float]
AgentsStepResult = Tuple[
    List[List[float]], List[bool], List[bool], Optional[str], Optional[str], float
]

class EnvCore:
    """The simulation behind ``mergesim.MergeEnv`` (one agent) and ``mergesim.parallel_env``
    (several). Agents: ``vehicle`` (one, any vehicle; None: ``ego`` or the first), ``agents``
    (these, each connected and planner-driven) or ``connected_agents=True`` (every connected,
    planner-driven vehicle); at most one of the three."""

    def __init__(
        self,
        scenario: str,
        params_json: Optional[str] = None,
        planner: Optional[str] = None,
        vehicle: Optional[str] = None,
        agents: Optional[Sequence[str]] = None,
        connected_agents: bool = False,
    ) -> None: ...
    def reset(self, seed: Optional[int] = None) -> List[List[float]]:
        """Starts an episode; returns every vehicle's state row (``state_columns``)."""
    def step(self, target_speed_mps: float, target_y_m: float) -> StepResult:
        """One planning period, commanding the (first) agent: (states, hit a vehicle, hit a road
        edge, vehicle at the road's end, simulation error, time s)."""
    def step_agents(self, commands: Sequence[Tuple[float, float]]) -> AgentsStepResult:
        """One planning period, one (target_speed_mps, target_y_m) per agent in agent order (a
        handed-back agent's is ignored): (states, per agent hit a vehicle, per agent hit a road
        edge, vehicle at the road's end, simulation error, time s)."""
    def hand_back(self, agent: int) -> None:
        """Agent ``agent``'s vehicle (its position in ``agent_indices``) is driven by its own
        planner until the next reset."""
    @property
    def agent_index(self) -> int:
        """The (first) agent's vehicle index."""
    @property
    def agent_indices(self) -> List[int]:
        """The agents' vehicle indices, in agent order."""
    @property
    def vehicle_names(self) -> List[str]: ...
    @property
    def vehicle_sizes_m(self) -> List[Tuple[float, float]]: ...
    @property
    def road(self) -> List[Tuple[str, float]]: ...
    @property
    def duration_s(self) -> float: ...
    @property
    def planner_period_s(self) -> float: ...
    @property
    def agent_target_speed_mps(self) -> float: ...
    @property
    def nominal_target_speed_mps(self) -> float: ...
    @property
    def agent_target_speeds_mps(self) -> List[float]: ...
    @property
    def nominal_target_speeds_mps(self) -> List[float]: ...
    @staticmethod
    def state_columns() -> List[str]: ...
