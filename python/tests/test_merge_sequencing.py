"""Merge sequencing (``pf-iso-seq``) from Python: the registry name flows through ``run``, its
parameter table is given through ``params`` as in a scenario file, and a bad value is refused
with merge_sim's message."""

from __future__ import annotations

import pytest

import mergesim


def test_the_dense_merge_with_sequencing_runs_without_collision() -> None:
    result = mergesim.run("dense_merge", planner="pf-iso-seq")
    assert result.summary["planner"] == "pf-iso-seq"
    assert result.summary["collisions"] == 0
    merges = [e for e in result.summary["events"] if "from lane 2 to lane 1" in e]
    assert len(merges) == 3, merges


def test_a_bad_sequencing_parameter_is_refused() -> None:
    with pytest.raises(mergesim.ScenarioError, match="side_headway_s"):
        mergesim.run(
            "dense_merge",
            planner="pf-iso-seq",
            params={"sim": {"planners": {"pf-iso-seq": {"side_headway_s": -1.0}}}},
        )
