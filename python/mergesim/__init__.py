"""mergesim from Python: cooperative merge simulations on Rapier vehicles.

- :func:`run` — one run: its summary (the ``merge_sim run --json`` dict) and time series
  (a pandas DataFrame with the ``--csv`` columns);
- :func:`sweep` — seeded Monte-Carlo sweeps of several planners over the same instances (paired
  by seed), run in parallel in Rust, as a pandas DataFrame;
- :func:`study` — a study plan (``merge_sim study PLAN.toml``) run in Rust, its report's tables
  as pandas DataFrames;
- :class:`MergeEnv` — a Gymnasium environment: the agent drives one vehicle through the
  simulator's tracker, the others run the scenario's planners (also registered as
  ``mergesim/Merge-v0``);
- :func:`parallel_env` — a PettingZoo ``ParallelEnv`` in which several connected vehicles are
  agents at once, with a cooperative reward (:class:`MergeParallelEnv`);
- :func:`register_planner` — a planner written in Python (``plan(observation) -> decision``)
  under a name, usable wherever a planner name goes (``run``, ``sweep``, ``study``,
  ``MergeEnv``);
- :class:`ScenarioError` (a ``ValueError``) for bad input, with ``merge_sim``'s message;
  :class:`SimulationError` (a ``RuntimeError``) for a failure while simulating.

See python/README.md.
"""

from ._native import Road, ScenarioError, SimulationError, builtin_scenarios, planners
from .env import MergeEnv, RewardWeights
from .parallel import MergeParallelEnv, TeamRewardWeights, parallel_env
from .planner import Planner, python_planners, register_planner, unregister_planner
from .run import RunResult, run
from .study import study
from .sweep import never_as_infinity, never_column, paired_differences, rows_frame, sweep

try:
    from importlib.metadata import version as _version

    __version__ = _version("mergesim")
except Exception:  # not installed (e.g. imported from the source tree)
    __version__ = "0+unknown"

__all__ = [
    "__version__",
    "MergeEnv",
    "MergeParallelEnv",
    "Planner",
    "RewardWeights",
    "Road",
    "RunResult",
    "ScenarioError",
    "SimulationError",
    "TeamRewardWeights",
    "builtin_scenarios",
    "never_as_infinity",
    "never_column",
    "paired_differences",
    "parallel_env",
    "planners",
    "python_planners",
    "register_planner",
    "rows_frame",
    "run",
    "study",
    "sweep",
    "unregister_planner",
]


def _register() -> None:
    import gymnasium

    if "mergesim/Merge-v0" not in gymnasium.registry:
        gymnasium.register(id="mergesim/Merge-v0", entry_point="mergesim.env:MergeEnv")


_register()
