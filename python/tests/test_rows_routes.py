"""A sweep's rows read the same by every route into pandas (JSONL with plain
``pd.read_json(lines=True)``, Parquet with ``pd.read_parquet``, the Python API), and a seed taken
from any of them replays its row."""

from __future__ import annotations

import json
import pathlib
import subprocess

import numpy as np
import pandas as pd
import pytest

import mergesim

PLANNERS = ["pf-cs", "pf-iso"]
RUNS = 6
SEED = 11

RUN_NEVER = {"min_ttc_s": "min_ttc_never", "min_gap_m": "min_gap_never"}
VEHICLE_NEVER = {"slowing_onset_s": "slowing_onset_never", "divider_crossing_t_s": "divider_crossing_never"}


@pytest.fixture
def closing(short_urgent_merge: pathlib.Path, tmp_path: pathlib.Path) -> pathlib.Path:
    """The 2 s urgent merge with the obstacle ahead in the ego's lane, at a cruise speed drawn
    from 14 to 25 m/s: slower than the ego, the pair closes (finite min TTC); faster, it never
    does (in the unchanged urgent merge no pair ever closes: every min TTC is "never")."""
    text = short_urgent_merge.read_text()
    for old, new in [
        ('lane = "upper"', 'lane = "lower"'),
        ("x_m = { uniform = [-3.0, 3.0] }",
         "x_m = { uniform = [-3.0, 3.0] }\ncruise_speed_mps = { uniform = [-1.0, 9.0] }"),
    ]:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "closing.toml"
    path.write_text(text)
    return path


@pytest.fixture
def cli_sweep(merge_sim: str, closing: pathlib.Path, tmp_path: pathlib.Path):
    """The CLI's JSONL and Parquet of one paired sweep of ``closing``."""
    jsonl, parquet = tmp_path / "rows.jsonl", tmp_path / "rows.parquet"
    subprocess.run(
        [merge_sim, "sweep", "--scenario", str(closing), "--planners", ",".join(PLANNERS),
         "--runs", str(RUNS), "--seed", str(SEED), "--quiet", "--jsonl", str(jsonl),
         "--parquet", str(parquet)],
        check=True,
    )
    return jsonl, parquet


def in_order(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.sort_values(["instance", "planner"]).reset_index(drop=True)


def test_seeds_survive_pandas(merge_sim: str, closing: pathlib.Path, cli_sweep, tmp_path: pathlib.Path) -> None:
    """Plain ``pd.read_json(lines=True)``, no dtype arguments: the seed it gives replays the row
    (before: pandas made the decimal-string seeds float64, and the replay ran another instance)."""
    jsonl, _ = cli_sweep
    rows = in_order(pd.read_json(jsonl, lines=True))
    assert len(rows) == RUNS * len(PLANNERS)
    checked = 0
    for index in [1, 4, 9]:
        row = rows.iloc[index]
        seed = row["seed"]
        assert isinstance(seed, str) and seed.startswith("0x"), repr(seed)
        replay = tmp_path / f"replay{index}.json"
        subprocess.run(
            [merge_sim, "run", "--scenario", str(closing), "--planner", row["planner"],
             "--seed", seed, "--no-rrd", "--quiet", "--json", str(replay)],
            check=True,
        )
        run = json.loads(replay.read_text())
        assert run["seed"] == seed
        for key in ["collisions", "tet_s", "near_miss"]:
            assert run[key] == row[key], key
        for key in ["min_gap_m", "min_ttc_s"]:
            if run[key] is None:
                assert np.isnan(row[key]) and row[RUN_NEVER[key]]
            else:
                assert run[key] == row[key], key
        # The Python API takes the same string, and the uint64 of the other routes.
        again = mergesim.run(closing, planner=row["planner"], seed=seed).summary
        assert again["min_gap_m"] == run["min_gap_m"] and again["seed"] == seed
        checked += 1
    assert checked == 3
    # The sweep seed and the instance replay it too.
    row = rows.iloc[7]
    assert row["sweep_seed"] == f"0x{SEED:016x}"
    by_index = mergesim.run(closing, planner=row["planner"], sweep_seed=row["sweep_seed"],
                            instance=int(row["instance"])).summary
    assert by_index["seed"] == row["seed"] and by_index["tet_s"] == row["tet_s"]


def test_a_seed_that_went_through_a_double_is_refused(merge_sim: str, short_urgent_merge: pathlib.Path) -> None:
    rounded = float(0x88BE3E3D6D9F1A2D)  # what pandas made of a decimal-string seed
    result = subprocess.run(
        [merge_sim, "run", "--scenario", str(short_urgent_merge), "--seed", repr(rounded), "--no-rrd", "--quiet"],
        capture_output=True, text=True,
    )
    assert result.returncode == 2, result.stderr
    assert "not a whole number" in result.stderr
    for bad in [rounded, np.float64(rounded), str(rounded), "12.0"]:
        with pytest.raises(mergesim.ScenarioError, match="seed"):
            mergesim.run(short_urgent_merge, seed=bad)


def test_never_reads_the_same_by_every_route(cli_sweep, closing: pathlib.Path) -> None:
    """"Never" is NaN plus a True ``..._never`` flag in the JSONL (plain ``read_json``), the
    Parquet file, the JSONL through ``rows_frame`` and the Python API's DataFrame."""
    jsonl, parquet = cli_sweep
    routes = {
        "read_json": in_order(pd.read_json(jsonl, lines=True)),
        "read_parquet": in_order(pd.read_parquet(parquet)),
        "rows_frame": in_order(mergesim.rows_frame(jsonl.read_text().splitlines())),
        "api": in_order(mergesim.sweep(closing, planners=PLANNERS, runs=RUNS, seed=SEED)),
    }
    reference = routes["read_parquet"]
    assert (reference["status"] == "completed").all()
    assert reference["min_ttc_never"].any(), "expected a run without a closing pair"
    assert not reference["min_ttc_never"].all(), "expected a run with a closing pair"
    for name, frame in routes.items():
        for figure, flag in RUN_NEVER.items():
            values, never = frame[figure].astype(float), frame[flag]
            assert never.dtype == bool, (name, flag, never.dtype)
            # The same values and flags as the Parquet file, NaN exactly where never.
            np.testing.assert_array_equal(values.to_numpy(), reference[figure].astype(float).to_numpy())
            assert list(never) == list(reference[flag]), (name, flag)
            assert list(values.isna()) == list(never), (name, figure)
        # Seeds: exact in every route (hex text from read_json, uint64 otherwise).
        seeds = [int(s, 16) if isinstance(s, str) else int(s) for s in frame["seed"]]
        assert seeds == [int(s) for s in reference["seed"]], name
        sweep_seeds = {int(s, 16) if isinstance(s, str) else int(s) for s in frame["sweep_seed"]}
        assert sweep_seeds == {SEED}, name
    # The flat routes agree on every vehicle's never flags too.
    for name in ["rows_frame", "api"]:
        frame = routes[name]
        for vehicle in ["ego", "obstacle"]:
            for figure, flag in VEHICLE_NEVER.items():
                column, flag_column = f"{vehicle}.{figure}", f"{vehicle}.{flag}"
                np.testing.assert_array_equal(
                    frame[column].astype(float).to_numpy(), reference[column].astype(float).to_numpy()
                )
                assert list(frame[flag_column]) == list(reference[flag_column]), (name, flag_column)
                assert list(frame[column].isna()) == list(frame[flag_column]), (name, column)
    # Counting never as +inf is explicit, and the same from every route.
    for name, frame in routes.items():
        inf = mergesim.never_as_infinity(frame, "min_ttc_s")
        assert list(np.isinf(inf)) == list(reference["min_ttc_never"]), name
        assert inf.median() == mergesim.never_as_infinity(reference, "min_ttc_s").median()


def test_a_figure_that_is_never_in_every_row_is_a_float_column(short_urgent_merge: pathlib.Path) -> None:
    """In the unchanged urgent merge no pair ever closes: min_ttc_s is "never" in every row, a
    column of NaN (float64, as read_json and read_parquet read it), not an object column of
    None; text columns stay text."""
    frame = mergesim.sweep(short_urgent_merge, planners=PLANNERS, runs=2, seed=SEED)
    assert frame["min_ttc_never"].all(), "expected no closing pair in any run"
    for column in ["min_ttc_s", "ego.slowing_onset_s", "obstacle.slowing_onset_s"]:
        if frame[column].isna().all():
            assert frame[column].dtype == np.float64, (column, frame[column].dtype)
    assert frame["min_ttc_s"].dtype == np.float64
    assert frame["min_ttc_s"].mean() != frame["min_ttc_s"].mean()  # NaN: skipped by mean()
    assert frame["planner"].dtype != np.float64 and set(frame["planner"]) == set(PLANNERS)
