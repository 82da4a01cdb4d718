"""``mergesim.sweep``: seeded Monte-Carlo sweeps of several planners over the same instances."""

from __future__ import annotations

import json
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence

import pandas as pd

from . import _native
from ._common import (
    ScenarioError,
    ScenarioSource,
    count_arg,
    optional_count_arg,
    params_json,
    scenario_arg,
    seed_arg,
)

#: Row fields that hold a 64-bit seed, written as strings in the JSONL (exact in every reader).
_SEED_FIELDS = ("seed", "sweep_seed")


def _flatten(prefix: str, value: Any, out: Dict[str, Any]) -> None:
    """Nested dicts become ``a.b`` columns (``drawn.sim.mu``); the per-vehicle figures (a list of
    dicts with a ``name``) become ``<vehicle>.<figure>`` columns, as in ``merge_sim sweep
    --parquet``; other lists become tuples."""
    if isinstance(value, Mapping):
        for key, inner in value.items():
            _flatten(f"{prefix}.{key}" if prefix else str(key), inner, out)
    elif (
        isinstance(value, list)
        and value
        and all(isinstance(v, Mapping) and "name" in v for v in value)
    ):
        base = "" if prefix == "vehicles" else prefix
        for item in value:
            label = str(item["name"])
            rest = {k: v for k, v in item.items() if k != "name"}
            _flatten(f"{base}.{label}" if base else label, rest, out)
    elif isinstance(value, list):
        out[prefix] = tuple(value)
    else:
        out[prefix] = value


def rows_frame(lines: Iterable[str]) -> pd.DataFrame:
    """The DataFrame of JSONL rows (``merge_sim sweep --jsonl``): one row per line, nested fields
    flattened as in ``merge_sim sweep --parquet`` (``drawn.<name>``, ``<vehicle>.<figure>``),
    seeds as unsigned 64-bit integers. Reads a ``--jsonl`` file too:
    ``rows_frame(open(path))``."""
    records: List[Dict[str, Any]] = []
    for line in lines:
        flat: Dict[str, Any] = {}
        _flatten("", json.loads(line), flat)
        records.append(flat)
    frame = pd.DataFrame.from_records(records)
    for field in _SEED_FIELDS:
        if field in frame.columns:
            frame[field] = frame[field].map(int).astype("uint64")
    return frame


def sweep(
    scenario: ScenarioSource,
    planners: Optional[Sequence[str]] = None,
    runs: int = 10,
    seed: int = 0,
    threads: Optional[int] = None,
    params: Optional[Mapping[str, Any]] = None,
) -> pd.DataFrame:
    """Sweeps ``runs`` randomised instances of a scenario for each planner, in parallel in Rust
    (the library's paired sweep: what ``merge_sim sweep --planners A,B --jsonl`` runs).

    Instance ``i`` runs with seed ``instance_seed(seed, i)`` for every planner, so the planners
    meet the same drawn scenarios and the rows are paired by ``instance`` (and ``seed``); any
    row replays alone with ``mergesim.run(scenario, planner, seed=row.seed)``. The results do
    not depend on ``threads``.

    Args:
        scenario: A built-in name, a path, or TOML text (as in :func:`mergesim.run`).
        planners: Planner names (``mergesim.planners()``), the first the baseline; None (or an
            empty list) runs the scenario's own planners once.
        runs: Instances per planner (1 to 1,000,000).
        seed: The sweep seed K (0 to 2**64-1).
        threads: Worker threads (None: one per core).
        params: Overrides merged over the scenario (as in :func:`mergesim.run`).

    Returns:
        One row per (instance, planner), in instance order, the planners of an instance in the
        given order, with the fields of ``merge_sim sweep --jsonl`` rows: scenario,
        scenario_fingerprint, params, planners (the sweep's, a tuple), sweep_seed, total_runs,
        instance, planner, seed, status, error (only if a run failed), ``drawn.<value>`` (what
        the instance drew), the run's figures (collisions, near_miss, min_ttc_s, min_gap_m,
        tet_s, peak_yaw_rate_radps, ...), ``<vehicle>.<figure>`` and wall_time_s.

    Raises:
        ScenarioError: Bad input (scenario, planner, runs, seed or threads).
    """
    if planners is None:
        planner_list: List[str] = []
    elif isinstance(planners, str):
        planner_list = [planners]
    else:
        planner_list = list(planners)
    for name in planner_list:
        if not isinstance(name, str):
            raise ScenarioError(f"planners: {name!r} is not a planner name")
    lines = _native.sweep(
        scenario_arg(scenario),
        planner_list,
        count_arg("runs", runs),
        seed_arg("seed", seed),
        params_json(params),
        optional_count_arg("threads", threads),
    )
    return rows_frame(lines)


def paired_differences(
    rows: pd.DataFrame, metric: str, baseline: str, other: str
) -> pd.Series:
    """``other − baseline`` of ``metric`` per instance, over the instances both completed.

    Args:
        rows: What :func:`sweep` returned (with both planners).
        metric: A numeric column, e.g. ``"min_gap_m"`` or ``"tet_s"``.
        baseline: The planner subtracted.
        other: The planner compared with it.

    Returns:
        The differences, indexed by instance.
    """
    if metric not in rows.columns:
        raise ScenarioError(f"metric {metric!r}: not a column of the rows")
    done = rows[rows["status"] == "completed"]
    table = done.pivot(index="instance", columns="planner", values=metric)
    for name in (baseline, other):
        if name not in table.columns:
            raise ScenarioError(f"planner {name!r}: not among the rows' planners")
    both = table[[baseline, other]].astype(float).dropna()
    return (both[other] - both[baseline]).rename(f"{metric} {other} - {baseline}")
