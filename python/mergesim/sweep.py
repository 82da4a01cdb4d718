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

#: Row fields that hold a 64-bit seed, written as ``"0x..."`` strings in the JSONL (exact in
#: every reader, pandas included); decimal strings of older files are read too.
_SEED_FIELDS = ("seed", "sweep_seed")

#: Row fields that hold text (null where absent, e.g. ``error`` of a completed run): never cast
#: to float, however many of them are null.
_TEXT_FIELDS = frozenset({"scenario", "scenario_fingerprint", "params", "planners", "planner",
                          "status", "error"})

#: Run-level figures whose ``null`` means "never" (+∞: no pair ever came within range / was ever
#: closing), each with the boolean column that says so.
NEVER_FLAGS = {"min_gap_m": "min_gap_never", "min_ttc_s": "min_ttc_never"}
#: The same for each vehicle's figures (``<vehicle>.<figure>`` → ``<vehicle>.<flag>``): never
#: slowed, never crossed the lane divider.
VEHICLE_NEVER_FLAGS = {
    "slowing_onset_s": "slowing_onset_never",
    "divider_crossing_t_s": "divider_crossing_never",
    "divider_crossing_x_m": "divider_crossing_never",
}


def never_column(column: str) -> Optional[str]:
    """The boolean column that says when ``column``'s missing value means "never" (+∞), e.g.
    ``"min_ttc_never"`` for ``"min_ttc_s"`` and ``"ego.slowing_onset_never"`` for
    ``"ego.slowing_onset_s"``; None for a figure without one."""
    if column in NEVER_FLAGS:
        return NEVER_FLAGS[column]
    if "." in column and not column.startswith("drawn."):
        vehicle, figure = column.rsplit(".", 1)
        if figure in VEHICLE_NEVER_FLAGS:
            return f"{vehicle}.{VEHICLE_NEVER_FLAGS[figure]}"
    return None


def never_as_infinity(rows: pd.DataFrame, column: str) -> pd.Series:
    """``column`` as floats with its "never" values as +∞ (where its ``..._never`` flag is true)
    and every other missing value (a failed run, a figure not measured) still NaN: for means,
    quantiles or orderings that count the runs where it never happened as the best / latest
    value rather than drop them. Works on the rows of :func:`sweep`, :func:`rows_frame`, and
    ``pandas.read_parquet`` of ``merge_sim sweep --parquet``."""
    if column not in rows.columns:
        raise ScenarioError(f"column {column!r}: not a column of the rows")
    try:
        values = rows[column].astype(float)
    except (TypeError, ValueError):
        raise ScenarioError(f"column {column!r}: not a numeric column") from None
    flag = never_column(column)
    if flag is None or flag not in rows.columns:
        return values
    never = rows[flag].eq(True).fillna(False).astype(bool)
    return values.where(~never, float("inf"))


def _seed_value(value: Any) -> int:
    if isinstance(value, str):
        return int(_native.parse_seed(value))
    return int(value)


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
    seeds (``seed``, ``sweep_seed``) as unsigned 64-bit integers. "Never" reads as in the JSONL
    and the Parquet file: the figure NaN and its ``..._never`` column True (``min_ttc_s`` /
    ``min_ttc_never``, ``min_gap_m`` / ``min_gap_never``, a vehicle's ``slowing_onset_s`` /
    ``slowing_onset_never`` and ``divider_crossing_t_s`` / ``divider_crossing_never``); a NaN
    with the flag False or missing is "not measured". pandas' ``mean()`` skips NaN: use
    :func:`never_as_infinity` to count the never runs as +∞ instead. Reads a ``--jsonl`` file
    too: ``rows_frame(open(path))``."""
    records: List[Dict[str, Any]] = []
    for line in lines:
        flat: Dict[str, Any] = {}
        _flatten("", json.loads(line), flat)
        records.append(flat)
    frame = pd.DataFrame.from_records(records)
    for field in _SEED_FIELDS:
        if field in frame.columns:
            frame[field] = frame[field].map(_seed_value).astype("uint64")
    # A figure that is null in every row (e.g. min_ttc_s when no pair ever closed) would be an
    # object column of None; it is a float column of NaN, as read_json and read_parquet give.
    for column in frame.columns:
        if column in _TEXT_FIELDS or frame[column].dtype != object:
            continue
        present = frame[column].dropna()
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
            frame[column] = frame[column].astype("float64")
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
    row replays alone with ``mergesim.run(scenario, planner, seed=row.seed)`` or
    ``mergesim.run(scenario, planner, sweep_seed=row.sweep_seed, instance=row.instance)``.
    The results do not depend on ``threads``.

    Args:
        scenario: A built-in name, a path, or TOML text (as in :func:`mergesim.run`).
        planners: Planner names (``mergesim.planners()``), the first the baseline, as a list or
            a comma-separated string (as ``--planners``); None (or an empty list) runs the
            scenario's own planners once.
        runs: Instances per planner (1 to 1,000,000).
        seed: The sweep seed K (0 to 2**64-1; a ``"0x..."`` string too).
        threads: Worker threads (None: one per core).
        params: Overrides merged over the scenario (as in :func:`mergesim.run`).

    Returns:
        One row per (instance, planner), in instance order, the planners of an instance in the
        given order, with the fields of ``merge_sim sweep --jsonl`` rows: scenario,
        scenario_fingerprint, params, planners (the sweep's, a tuple), sweep_seed, total_runs,
        instance, planner, seed, status, error (only if a run failed), ``drawn.<value>`` (what
        the instance drew), the run's figures (collisions, near_miss, min_ttc_s,
        min_ttc_never, min_gap_m, min_gap_never, tet_s, peak_yaw_rate_radps, ...,
        shield_interventions, throughput_vph, merging_vehicles, merged_before_lane_end,
        mean_delay_s),
        ``<vehicle>.<figure>`` and wall_time_s. "Never" is NaN with its ``..._never`` flag
        True, as in the JSONL and the Parquet file (see :func:`rows_frame`).

    Raises:
        ScenarioError: Bad input (scenario, planner, runs, seed or threads).
    """
    if planners is None:
        planner_list: List[str] = []
    elif isinstance(planners, str):
        # As on the command line: "pf-cs,pf-iso" is two planners.
        planner_list = [name.strip() for name in planners.split(",")]
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
    """``other − baseline`` of ``metric`` per instance, over the instances both completed (and,
    for a ``<vehicle>.<figure>``, where both have a value or a "never").

    "Never" counts as +∞ (:func:`never_as_infinity`). A figure that is never in both rows (e.g.
    ``min_ttc_s`` when no pair ever closed with either planner) gives 0 (a tie, as
    ``merge_sim sweep`` counts it); never in one gives ±∞. So
    ``(d > 0).sum()``, ``(d < 0).sum()`` and ``(d == 0).sum()`` are the CLI's higher / lower /
    tied counts, and the CLI's mean difference ± SE is that of the finite differences.

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
    values = never_as_infinity(rows, metric)
    done = rows.assign(**{metric: values})[rows["status"] == "completed"]
    table = done.pivot(index="instance", columns="planner", values=metric)
    for name in (baseline, other):
        if name not in table.columns:
            raise ScenarioError(f"planner {name!r}: not among the rows' planners")
    if baseline == other:
        raise ScenarioError(f"baseline and other are the same planner {baseline!r}")
    try:
        both = table[[baseline, other]].astype(float).dropna()
    except (TypeError, ValueError):
        raise ScenarioError(f"metric {metric!r}: not a numeric column") from None
    both_infinite = (both[other] == float("inf")) & (both[baseline] == float("inf"))
    difference = (both[other] - both[baseline]).where(~both_infinite, 0.0)
    return difference.rename(f"{metric} {other} - {baseline}")
