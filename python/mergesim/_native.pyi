"""Type stubs of the native module (Rust, PyO3). Use the wrappers in ``mergesim`` instead."""

from typing import List, Optional, Sequence, Tuple

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
    """Names of the built-in planners."""

StepResult = Tuple[List[List[float]], bool, bool, Optional[str], Optional[str], float]

class EnvCore:
    """The simulation behind ``mergesim.MergeEnv``."""

    def __init__(
        self,
        scenario: str,
        params_json: Optional[str] = None,
        planner: Optional[str] = None,
        vehicle: Optional[str] = None,
    ) -> None: ...
    def reset(self, seed: Optional[int] = None) -> List[List[float]]:
        """Starts an episode; returns every vehicle's state row (``state_columns``)."""
    def step(self, target_speed_mps: float, target_y_m: float) -> StepResult:
        """One planning period: (states, hit a vehicle, hit a road edge, vehicle at the road's
        end, simulation error, time s)."""
    @property
    def agent_index(self) -> int: ...
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
    @staticmethod
    def state_columns() -> List[str]: ...
