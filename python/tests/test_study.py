"""mergesim.study: a study plan run from Python returns the report's tables as DataFrames, the
same tables ``merge_sim study`` writes."""

from __future__ import annotations

import json
import pathlib
import subprocess

import pandas as pd
import pytest

import mergesim

PLAN = """name = "py_small"
scenario = "urgent_merge"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"

[instances]
n = 3
seed = 5

[factors]
"sim.duration_s" = [2.0]
"sim.mu" = [0.8, 0.6]

[endpoints]
primary = { figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }
secondary = [{ figure = "ego.min_speed_mps", threshold = "0.5 m/s" }]
"""


@pytest.fixture(scope="module")
def plan(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    path = tmp_path_factory.mktemp("study") / "plan.toml"
    path.write_text(PLAN)
    return path


@pytest.fixture(scope="module")
def tables(plan: pathlib.Path) -> dict:
    return mergesim.study(plan, threads=2)


def test_tables_are_dataframes(tables: dict) -> None:
    endpoints = tables["endpoints"]
    collisions = tables["collisions"]
    assert isinstance(endpoints, pd.DataFrame) and isinstance(collisions, pd.DataFrame)
    # 2 cells × 1 planner pair × 2 motion-state endpoints × 2 windows.
    assert len(endpoints) == 8
    for column in ["cell_label", "planner", "reference", "endpoint", "window", "n", "mean_difference",
                   "ci95_low", "ci95_high", "p_t", "p_wilcoxon", "p_t_holm", "median_difference",
                   "p90_difference", "threshold", "verdict"]:
        assert column in endpoints.columns, column
    assert set(endpoints["planner"]) == {"pf-iso"}
    assert set(endpoints["reference"]) == {"pf-sp"}
    assert (endpoints["n"] + endpoints["n_excluded"] == 3).all()
    assert len(collisions) == 2
    assert {"both", "only_planner", "only_reference", "neither", "p_mcnemar"} <= set(collisions.columns)
    assert (collisions[["both", "only_planner", "only_reference", "neither"]].sum(axis=1) == 3).all()
    report = tables["report"]
    assert report["provenance"]["exploratory"] is True  # a plan outside git
    assert report["reference"] == "pf-sp"


def test_the_tables_equal_the_cli_report(merge_sim: str, plan: pathlib.Path, tables: dict,
                                          tmp_path: pathlib.Path) -> None:
    out = tmp_path / "report"
    subprocess.run([merge_sim, "study", str(plan), "--out", str(out), "--quiet"], check=True)
    cli = json.loads((out / "report.json").read_text())
    assert cli["analysis"] == tables["report"]["analysis"]
    csv = pd.read_csv(out / "endpoints.csv")
    assert list(csv["mean_difference"]) == pytest.approx(list(tables["endpoints"]["mean_difference"]))


def test_a_bad_plan_raises_scenario_error(tmp_path: pathlib.Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(PLAN.replace('"0.5 m/s"', "0.5"))
    with pytest.raises(mergesim.ScenarioError, match=r"bad.toml, line 16: .*without a unit"):
        mergesim.study(bad)
