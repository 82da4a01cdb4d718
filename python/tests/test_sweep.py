"""mergesim.sweep: paired rows (same instances for every planner), deterministic, replayable."""

from __future__ import annotations

import pathlib
import subprocess

import pandas as pd
import pytest

import mergesim

from conftest import SHORT

PLANNERS = ["pf-cs", "pf-iso"]


@pytest.fixture(scope="module")
def rows() -> pd.DataFrame:
    return mergesim.sweep("urgent_merge", planners=PLANNERS, runs=3, seed=11, params=SHORT, threads=2)


def test_rows_equal_the_cli_jsonl(merge_sim: str, short_urgent_merge: pathlib.Path, tmp_path: pathlib.Path) -> None:
    jsonl = tmp_path / "rows.jsonl"
    subprocess.run(
        [merge_sim, "sweep", "--scenario", str(short_urgent_merge), "--planners", ",".join(PLANNERS),
         "--runs", "3", "--seed", "11", "--quiet", "--jsonl", str(jsonl)],
        check=True,
    )
    cli = mergesim.rows_frame(jsonl.read_text().splitlines())
    ours = mergesim.sweep(short_urgent_merge, planners=PLANNERS, runs=3, seed=11)
    cli = cli.sort_values(["instance", "planner"]).reset_index(drop=True)
    assert list(ours.columns) == list(cli.columns)
    pd.testing.assert_frame_equal(
        ours.drop(columns="wall_time_s").reset_index(drop=True), cli.drop(columns="wall_time_s")
    )


def test_one_row_per_instance_and_planner(rows: pd.DataFrame) -> None:
    assert len(rows) == 6
    assert sorted(set(rows["planner"])) == PLANNERS
    assert set(rows["instance"]) == {0, 1, 2}
    assert (rows["status"] == "completed").all()
    for column in ["seed", "collisions", "min_gap_m", "tet_s", "near_miss", "wall_time_s"]:
        assert column in rows.columns, column
    assert rows["seed"].dtype == "uint64"
    assert {"drawn.sim.mu", "ego.min_speed_mps", "obstacle.collided"} <= set(rows.columns)
    assert list(rows["instance"]) == [0, 0, 1, 1, 2, 2]
    assert list(rows["planner"]) == PLANNERS * 3


def test_planners_meet_the_same_instances(rows: pd.DataFrame) -> None:
    by_planner = [rows[rows["planner"] == p].set_index("instance").sort_index() for p in PLANNERS]
    assert (by_planner[0]["seed"] == by_planner[1]["seed"]).all()
    drawn = [c for c in rows.columns if c.startswith("drawn.")]
    for column in drawn:
        assert (by_planner[0][column] == by_planner[1][column]).all(), column


def test_threads_change_nothing(rows: pd.DataFrame) -> None:
    again = mergesim.sweep("urgent_merge", planners=PLANNERS, runs=3, seed=11, params=SHORT, threads=1)
    pd.testing.assert_frame_equal(rows.drop(columns="wall_time_s"), again.drop(columns="wall_time_s"))


def test_a_row_replays_with_run(rows: pd.DataFrame) -> None:
    row = rows[(rows["planner"] == "pf-iso") & (rows["instance"] == 1)].iloc[0]
    # The row's seed as it is (numpy.uint64), as python/README.md says.
    summary = mergesim.run("urgent_merge", planner=row["planner"], seed=row["seed"], params=SHORT).summary
    assert summary["collisions"] == row["collisions"]
    assert summary["tet_s"] == row["tet_s"]
    assert summary["min_gap_m"] == row["min_gap_m"]


def test_paired_differences(rows: pd.DataFrame) -> None:
    diff = mergesim.paired_differences(rows, "min_speed_mps", "pf-cs", "pf-iso")
    assert list(diff.index) == [0, 1, 2]
    with pytest.raises(mergesim.ScenarioError):
        mergesim.paired_differences(rows, "min_speed_mps", "pf-cs", "pf-sp")


def test_never_is_flagged_and_tied(rows: pd.DataFrame) -> None:
    """null = never (no pair ever closing): NaN in the rows with ``min_ttc_never`` True, as in
    the JSONL and the Parquet file; counted as +inf by never_as_infinity and in the paired
    differences, both never = a tie, as the CLI counts it."""
    never = rows["min_ttc_never"]
    assert never.dtype == bool
    assert never.any(), "expected some run without a closing pair in 2 s of urgent_merge"
    assert list(rows["min_ttc_s"].isna()) == list(never)
    assert list(mergesim.never_as_infinity(rows, "min_ttc_s") == float("inf")) == list(never)
    diff = mergesim.paired_differences(rows, "min_ttc_s", "pf-cs", "pf-iso")
    assert list(diff.index) == [0, 1, 2]
    both_never = rows[never].groupby("instance").size() == 2
    for instance in both_never[both_never].index:
        assert diff[instance] == 0.0


def test_paired_differences_agree_with_the_cli_counts(
    merge_sim: str, short_urgent_merge: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    summary = tmp_path / "paired.json"
    subprocess.run(
        [merge_sim, "sweep", "--scenario", str(short_urgent_merge), "--planners", ",".join(PLANNERS),
         "--runs", "3", "--seed", "11", "--quiet", "--json", str(summary)],
        check=True,
    )
    import json

    cli = {
        (d["vehicle"], d["metric"]): d
        for d in json.loads(summary.read_text())["paired_differences"]
    }
    ours = mergesim.sweep(short_urgent_merge, planners=",".join(PLANNERS), runs=3, seed=11)
    for column, key in [("min_ttc_s", (None, "min_ttc_s")), ("min_gap_m", (None, "min_gap_m")),
                        ("ego.slowing_onset_s", ("ego", "slowing_onset_s"))]:
        diff = mergesim.paired_differences(ours, column, *PLANNERS)
        figure = cli[key]
        assert int((diff < 0).sum()) == figure["lower"], column
        assert int((diff > 0).sum()) == figure["higher"], column
        assert int((diff == 0).sum()) == figure["tied"], column


def test_paired_differences_bad_input(rows: pd.DataFrame) -> None:
    with pytest.raises(mergesim.ScenarioError, match="same planner"):
        mergesim.paired_differences(rows, "min_gap_m", "pf-cs", "pf-cs")
    with pytest.raises(mergesim.ScenarioError, match="not a numeric column"):
        mergesim.paired_differences(rows, "status", "pf-cs", "pf-iso")
