"""The RSS shield and the lane-changing human driver from Python: ``params`` selects them exactly
as a scenario file does, and bad values are refused with merge_sim's message."""

from __future__ import annotations

import pytest

import mergesim


def test_the_shield_is_selected_through_params_and_counted() -> None:
    off = mergesim.run("urgent_merge", params={"sim": {"duration_s": 3.0}})
    on = mergesim.run("urgent_merge", params={"sim": {"duration_s": 3.0, "shield": "rss"}})
    assert off.summary["shield_interventions"] == 0
    events = [e for e in on.summary["events"] if "the shield of" in e]
    assert on.summary["shield_interventions"] == len(events)


def test_bad_shield_values_are_refused() -> None:
    with pytest.raises(mergesim.ScenarioError, match="shield"):
        mergesim.run("urgent_merge", params={"sim": {"shield": "rsss"}})
    with pytest.raises(mergesim.ScenarioError, match="rss.brake_min_mps2"):
        mergesim.run("urgent_merge", params={"sim": {"rss": {"brake_min_mps2": 0.0}}})


def test_an_idm_mobil_driver_is_selected_through_params() -> None:
    # The ego of the urgent merge as a human driver who changes lanes: it leaves the ending
    # lane (a lane-change event) without touching anything.
    result = mergesim.run(
        "urgent_merge",
        params={
            "sim": {"duration_s": 10.0, "mobil": {"politeness": 0.5}},
            "vehicles": [
                {
                    "name": "ego",
                    "preset": "bmw_320i",
                    "lane": "lower",
                    "x_m": 0.0,
                    "speed_mps": 20.0,
                    "target_speed_mps": 20.0,
                    "driver": "idm-mobil",
                },
                {
                    "name": "obstacle",
                    "preset": "bmw_320i",
                    "lane": "upper",
                    "x_m": 35.0,
                    "speed_mps": 15.0,
                    "target_speed_mps": 15.0,
                    "driver": {"planner": "pf-iso"},
                },
            ],
        },
    )
    assert result.summary["collisions"] == 0
    assert any("ego changed lanes left" in e for e in result.summary["events"])
    with pytest.raises(mergesim.ScenarioError, match="mobil.politeness"):
        mergesim.run("urgent_merge", params={"sim": {"mobil": {"politeness": -1.0}}})
