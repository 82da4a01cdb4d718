"""mergesim.run: the same summary and time series as `merge_sim run --json --csv`."""

from __future__ import annotations

import json
import pathlib
import subprocess

import pandas as pd
import pytest

import mergesim

from conftest import SHORT


def without_wall_time(summary: dict) -> dict:
    """The summary without the figures measured in wall-clock time (they differ between runs)."""
    out = {k: v for k, v in summary.items() if k != "wall_time_s"}
    out["planner_stats"] = {
        k: v for k, v in summary["planner_stats"].items() if k not in ("p50_plan_us", "p99_plan_us")
    }
    return out


def test_run_matches_the_cli(merge_sim: str, short_urgent_merge: pathlib.Path, tmp_path: pathlib.Path) -> None:
    json_path, csv_path = tmp_path / "run.json", tmp_path / "run.csv"
    subprocess.run(
        [merge_sim, "run", "--scenario", str(short_urgent_merge), "--seed", "7", "--planner", "pf-sp",
         "--no-rrd", "--quiet", "--json", str(json_path), "--csv", str(csv_path)],
        check=True,
    )
    result = mergesim.run(short_urgent_merge, planner="pf-sp", seed=7)
    assert without_wall_time(result.summary) == without_wall_time(json.loads(json_path.read_text()))
    # The seed as the files write it, and the values it drew (as a sweep row's `drawn`).
    assert result.summary["seed"] == "0x0000000000000007"
    assert result.summary["drawn"]["sim.mu"] > 0 and "vehicles.ego.speed_mps" in result.summary["drawn"]
    pd.testing.assert_frame_equal(result.time_series, pd.read_csv(csv_path))


def test_summary_and_time_series_shape() -> None:
    result = mergesim.run("urgent_merge", params=SHORT)
    s = result.summary
    assert s["scenario"] == "urgent_merge" and s["planner"] == "pf-iso" and s["seed"] is None
    assert s["duration_s"] == pytest.approx(2.0)
    assert [v["id"] for v in s["vehicles"]] == ["ego", "obstacle"]
    ts = result.time_series
    assert {"t_s", "vehicle", "x_m", "y_m", "speed_mps"} <= set(ts.columns)
    assert set(ts["vehicle"]) == {"ego", "obstacle"}
    assert ts["t_s"].max() == pytest.approx(2.0)


def test_same_seed_same_run_and_toml_text_equals_file(short_urgent_merge: pathlib.Path) -> None:
    a = mergesim.run(short_urgent_merge, seed=3)
    b = mergesim.run(short_urgent_merge.read_text(), seed=3)
    assert without_wall_time(a.summary) == without_wall_time(b.summary)
    pd.testing.assert_frame_equal(a.time_series, b.time_series)
    c = mergesim.run(short_urgent_merge, seed=4)
    assert not a.time_series.equals(c.time_series)


def test_params_merge_over_the_scenario() -> None:
    result = mergesim.run("urgent_merge", params={"sim": {"duration_s": 1.0, "mu": 0.5}, "params": "paper"})
    assert result.summary["duration_s"] == pytest.approx(1.0)
    assert result.summary["params"] == "paper"
