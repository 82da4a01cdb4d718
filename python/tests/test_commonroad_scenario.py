"""A CommonRoad file as a scenario in Python: the same run as `merge_sim run --scenario FILE.xml`,
and the recorded traffic's mode set through `params`."""

from __future__ import annotations

import json
import pathlib
import subprocess

import pytest

import mergesim

ROOT = pathlib.Path(__file__).resolve().parents[2]
Y_MERGE = ROOT / "tests" / "data" / "commonroad" / "own" / "y_merge.xml"
NONE = {"sim": {"lane_road": {"commonroad": {"recorded_traffic": "none"}}}}


def test_an_xml_scenario_runs_as_on_the_cli(merge_sim: str, tmp_path: pathlib.Path) -> None:
    json_path = tmp_path / "run.json"
    subprocess.run(
        [merge_sim, "run", "--scenario", str(Y_MERGE), "--recorded-traffic", "none", "--no-rrd", "--quiet",
         "--json", str(json_path)],
        check=True,
    )
    cli = json.loads(json_path.read_text())
    result = mergesim.run(Y_MERGE, params=NONE)
    assert result.summary["goal_reached"] is True
    assert result.summary["goal_time_s"] == cli["goal_time_s"]
    assert result.summary["vehicles"] == cli["vehicles"]


def test_a_bad_mode_is_a_scenario_error() -> None:
    with pytest.raises(mergesim.ScenarioError, match="recorded_traffic"):
        mergesim.run(Y_MERGE, params={"sim": {"lane_road": {"commonroad": {"recorded_traffic": "often"}}}})


US101 = ROOT / "tests" / "data" / "commonroad" / "USA_US101-4_1_T-1.xml"


def test_sweep_rows_on_a_commonroad_road_carry_its_figures() -> None:
    rows = mergesim.sweep(US101, planners=["pf-iso"], runs=2, seed=0)
    assert list(rows["recorded_traffic"]) == ["replay", "replay"]
    # `merge_sim run` on this file counted 2 (2026-12-02).
    assert (rows["collisions_caused_by_replay"] > 0).all()
    assert rows["goal_reached"].notna().all()
    for column in ("min_gap_to_recorded_m", "min_ttc_to_recorded_s", "goal_time_s"):
        assert column in rows.columns, column
    builtin = mergesim.sweep("urgent_merge", planners=["pf-iso"], runs=1, seed=0)
    assert "recorded_traffic" not in builtin.columns
    assert "collisions_caused_by_replay" not in builtin.columns
