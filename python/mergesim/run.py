"""``mergesim.run``: one simulation, as ``merge_sim run --json --csv`` makes it."""

from __future__ import annotations

import io
import json
from dataclasses import dataclass
from typing import Any, Dict, Mapping, Optional

import pandas as pd

from . import _native
from ._common import ScenarioSource, optional_seed_arg, params_json, scenario_arg


@dataclass(frozen=True)
class RunResult:
    """A finished run.

    Attributes:
        summary: The run's summary, the dict ``merge_sim run --json`` prints (scenario,
            planner, params, seed as a string or None, duration_s, wall_time_s, collisions,
            min_gap_m, min_ttc_s, near_miss, tet_s, vehicles, planner_stats, events).
        time_series: One row per vehicle per logged instant (20 Hz by default), with the
            columns of ``merge_sim run --csv``.
    """

    summary: Dict[str, Any]
    time_series: pd.DataFrame


def run(
    scenario: ScenarioSource,
    planner: Optional[str] = None,
    seed: Optional[int] = None,
    params: Optional[Mapping[str, Any]] = None,
) -> RunResult:
    """Runs one instance of a scenario.

    Args:
        scenario: A built-in name (``mergesim.builtin_scenarios()``), a path to a scenario TOML
            file, or TOML text (a string with a line break).
        planner: Replaces every ``driver = { planner = ... }`` (``mergesim.planners()``); None
            keeps the scenario's.
        seed: None runs the nominal scenario; an integer runs the instance drawn with that seed
            from the scenario's ``[randomise]`` ranges (``merge_sim run --seed``).
        params: Overrides merged over the scenario's TOML before it is checked: a dict of its
            tables and keys, e.g. ``{"sim": {"mu": 0.5, "duration_s": 5.0}}`` or
            ``{"params": "paper"}``. Tables merge key by key; any other value (a number, a
            string, the ``vehicles`` list) replaces the scenario's.

    Returns:
        The summary and the time series.

    Raises:
        ScenarioError: Bad input (the message is ``merge_sim``'s exit-code-2 message).
        SimulationError: The simulation failed while running.
    """
    summary, csv = _native.run(
        scenario_arg(scenario),
        params_json(params),
        planner,
        optional_seed_arg("seed", seed),
    )
    return RunResult(summary=json.loads(summary), time_series=pd.read_csv(io.StringIO(csv)))
