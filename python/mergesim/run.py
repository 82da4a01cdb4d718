"""``mergesim.run``: one simulation, as ``merge_sim run --json --csv`` makes it."""

from __future__ import annotations

import io
import json
import operator
from dataclasses import dataclass
from typing import Any, Dict, Mapping, Optional, Union

import pandas as pd

from . import _native
from ._common import ScenarioError, ScenarioSource, optional_seed_arg, params_json, scenario_arg, seed_arg


@dataclass(frozen=True)
class RunResult:
    """A finished run.

    Attributes:
        summary: The run's summary, the dict ``merge_sim run --json`` prints (scenario,
            planner, params, seed as a ``"0x..."`` string or None, ``drawn`` (with a seed: the
            values it drew, by dotted name with units), duration_s, wall_time_s, collisions,
            collisions_caused_by_replay, min_gap_m, min_ttc_s, min_gap_to_recorded_m,
            min_ttc_to_recorded_s, near_miss, tet_s, shield_interventions, traffic
            (throughput through the merge, merging before the lane's end, delay and speed
            loss against free flow, per vehicle and per class), vehicles, planner_stats,
            events).
        time_series: One row per vehicle per logged instant (20 Hz by default), with the
            columns of ``merge_sim run --csv``.
    """

    summary: Dict[str, Any]
    time_series: pd.DataFrame


def run(
    scenario: ScenarioSource,
    planner: Optional[str] = None,
    seed: Optional[Union[int, str]] = None,
    params: Optional[Mapping[str, Any]] = None,
    sweep_seed: Optional[Union[int, str]] = None,
    instance: Optional[int] = None,
) -> RunResult:
    """Runs one instance of a scenario.

    Args:
        scenario: A built-in name (``mergesim.builtin_scenarios()``), a path to a scenario TOML
            file, or TOML text (a string with a line break).
        planner: Replaces every ``driver = { planner = ... }`` (``mergesim.planners()``); None
            keeps the scenario's.
        seed: None runs the nominal scenario; a seed runs the instance drawn with it from the
            scenario's ``[randomise]`` ranges (``merge_sim run --seed``): an integer (a sweep
            row's uint64 ``seed`` as it is) or a string as the files write it (``"0x..."``, or
            decimal digits). A float is refused (:class:`ScenarioError`): it cannot be exact.
        params: Overrides merged over the scenario's TOML before it is checked: a dict of its
            tables and keys, e.g. ``{"sim": {"mu": 0.5, "duration_s": 5.0}}`` or
            ``{"params": "paper"}``. Tables merge key by key; any other value (a number, a
            string, the ``vehicles`` list) replaces the scenario's.
        sweep_seed: With ``instance``, instead of ``seed``: run instance ``instance`` of the
            sweep with this seed, exactly the run of that sweep's row (``merge_sim run
            --sweep-seed K --instance I``; the rows carry ``sweep_seed`` and ``instance``).
        instance: The instance index of ``sweep_seed``.

    Returns:
        The summary and the time series.

    Raises:
        ScenarioError: Bad input (the message is ``merge_sim``'s exit-code-2 message).
        SimulationError: The simulation failed while running.
    """
    if (sweep_seed is None) != (instance is None):
        raise ScenarioError("sweep_seed and instance: give both (or neither)")
    if sweep_seed is not None:
        if seed is not None:
            raise ScenarioError("seed and sweep_seed: give one of them, not both")
        index = instance if not isinstance(instance, bool) else None
        try:
            index = None if index is None else operator.index(index)
        except TypeError:
            index = None
        if index is None or not 0 <= index <= 2**64 - 1:
            raise ScenarioError(f"instance = {instance!r}: need an integer from 0 to {2**64 - 1}")
        chosen: Optional[int] = _native.instance_seed(seed_arg("sweep_seed", sweep_seed), index)
    else:
        chosen = optional_seed_arg("seed", seed)
    summary, csv = _native.run(
        scenario_arg(scenario),
        params_json(params),
        planner,
        chosen,
    )
    return RunResult(summary=json.loads(summary), time_series=pd.read_csv(io.StringIO(csv)))
