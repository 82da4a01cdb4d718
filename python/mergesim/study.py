"""``mergesim.study``: a study plan (``merge_sim study PLAN.toml``) run from Python, its report's
tables as pandas DataFrames."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Union

import pandas as pd

from . import _native
from ._common import ScenarioError, optional_count_arg

#: The tables :func:`study` returns, by key.
TABLES = ("endpoints", "collisions", "failed_runs")


def _frame(records: Any, key: str) -> pd.DataFrame:
    frame = pd.DataFrame.from_records(records)
    if key == "endpoints" and len(frame):
        # The CI as two columns, as in endpoints.csv.
        ci = frame.pop("ci95")
        frame["ci95_low"] = [c[0] if c is not None else float("nan") for c in ci]
        frame["ci95_high"] = [c[1] if c is not None else float("nan") for c in ci]
    if key == "collisions" and len(frame):
        ci = frame.pop("ci95")
        frame["ci95_low"] = [c[0] if c is not None else float("nan") for c in ci]
        frame["ci95_high"] = [c[1] if c is not None else float("nan") for c in ci]
    if "seed" in frame.columns:
        # Seeds are strings in the JSON (exact in every reader): unsigned 64-bit integers here.
        frame["seed"] = frame["seed"].map(int).astype("uint64")
    return frame


def study(
    plan: Union[str, "os.PathLike[str]"],
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """Runs the study plan at ``plan`` (what ``merge_sim study PLAN.toml`` runs, in parallel in
    Rust) and returns its report's tables.

    Args:
        plan: Path of the plan file (``merge_sim study --help`` explains the format).
        out: If given, also write the report folder there (as ``merge_sim study --out``).
        threads: Worker threads (None: one per core); the results do not depend on it.

    Returns:
        A dict with ``endpoints`` (one row per cell, planner, endpoint and window: n, means,
        mean_difference, ci95_low/high, p_t, p_wilcoxon, Holm-adjusted p-values, median and p90
        of the differences, threshold, verdict), ``collisions`` (the 2×2 discordance table,
        exact McNemar p, the paired difference of collision proportions with its 95 % CI) and
        ``failed_runs`` as DataFrames, and ``report``: the whole ``report.json`` as a dict
        (provenance: the plan's git blob hash, the commit that first added it, the simulator's
        commit, whether it is exploratory).

    Raises:
        ScenarioError: A bad plan (the message names the file, line and field).
        SimulationError: A failure while running.
    """
    if not isinstance(plan, (str, os.PathLike)):
        raise ScenarioError(f"plan: expected a path, got {type(plan).__name__}")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise ScenarioError(f"out: expected a path, got {type(out).__name__}")
    text = _native.study(
        os.fspath(plan),
        None if out is None else os.fspath(out),
        optional_count_arg("threads", threads),
    )
    report = json.loads(text)
    tables: Dict[str, Any] = {key: _frame(report["analysis"][key], key) for key in TABLES}
    tables["report"] = report
    return tables
