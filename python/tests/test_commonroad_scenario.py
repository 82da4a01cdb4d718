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
