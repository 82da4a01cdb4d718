"""Bad input raises mergesim.ScenarioError with merge_sim's exit-code-2 message."""

from __future__ import annotations

import pathlib
import subprocess

import pytest

import mergesim

BAD_VALUE = """name = "bad"
[sim]
mu = 5.0
[[vehicles]]
name = "ego"
preset = "bmw_320i"
lane = "lower"
x_m = 0.0
speed_mps = 20.0
target_speed_mps = 20.0
driver = { planner = "pf-iso" }
"""

BAD_SYNTAX = 'name = "bad"\n[sim\nmu = 0.8\n'
UNKNOWN_KEY = BAD_VALUE.replace("mu = 5.0", "mu = 0.8\nfrobnicate = 1")


def cli_error(merge_sim: str, scenario: str) -> str:
    done = subprocess.run(
        [merge_sim, "run", "--scenario", scenario, "--no-rrd", "--quiet"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("error: ")
    return done.stderr[len("error: "):].rstrip("\n")


@pytest.mark.parametrize("text", [BAD_VALUE, BAD_SYNTAX, UNKNOWN_KEY], ids=["value", "syntax", "key"])
def test_bad_file_same_message_as_the_cli(merge_sim: str, tmp_path: pathlib.Path, text: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    expected = cli_error(merge_sim, str(path))
    with pytest.raises(mergesim.ScenarioError) as raised:
        mergesim.run(str(path))
    assert str(raised.value) == expected
    with pytest.raises(mergesim.ScenarioError) as raised:
        mergesim.sweep(path, planners=["pf-cs"], runs=1)
    assert str(raised.value) == expected
    with pytest.raises(mergesim.ScenarioError) as raised:
        mergesim.MergeEnv(path)
    assert str(raised.value) == expected


def test_unknown_scenario_same_message_as_the_cli(merge_sim: str) -> None:
    expected = cli_error(merge_sim, "no_such_scenario")
    with pytest.raises(mergesim.ScenarioError) as raised:
        mergesim.run("no_such_scenario")
    assert str(raised.value) == expected


def test_scenario_error_is_a_value_error() -> None:
    assert issubclass(mergesim.ScenarioError, ValueError)
    assert issubclass(mergesim.SimulationError, RuntimeError)


def test_bad_text_names_the_string() -> None:
    with pytest.raises(mergesim.ScenarioError, match=r"^<string>, line 3: invalid parameter mu = 5"):
        mergesim.run(BAD_VALUE)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: mergesim.run("urgent_merge", planner="pf-nope"), "pf-nope"),
        (lambda: mergesim.run("urgent_merge", seed=-1), "seed = -1"),
        (lambda: mergesim.run("urgent_merge", params={"sim": {"mu": 9.0}}), "mu = 9"),
        (lambda: mergesim.run("urgent_merge", params={"sim": {"mu": None}}), "params"),
        (lambda: mergesim.run("urgent_merge", params=[1]), "params"),
        (lambda: mergesim.run(42), "scenario"),
        (lambda: mergesim.sweep("urgent_merge", planners=["pf-nope"], runs=1), "pf-nope"),
        (lambda: mergesim.sweep("urgent_merge", planners=[None], runs=1), "not a planner name"),
        (lambda: mergesim.sweep("urgent_merge", planners=["pf-cs", "pf-cs"], runs=1), "pf-cs"),
        (lambda: mergesim.sweep("urgent_merge", runs=0), "runs = 0"),
        (lambda: mergesim.sweep("urgent_merge", runs=1, threads=0), "threads = 0"),
        (lambda: mergesim.MergeEnv("urgent_merge", vehicle="nobody"), "nobody"),
        (lambda: mergesim.MergeEnv("urgent_merge", planner="pf-nope"), "pf-nope"),
        (lambda: mergesim.MergeEnv("urgent_merge", render_mode="human"), "render_mode"),
    ],
)
def test_bad_arguments_raise_scenario_error(call, match: str) -> None:
    with pytest.raises(mergesim.ScenarioError, match=match):
        call()


def test_step_before_reset() -> None:
    env = mergesim.MergeEnv("urgent_merge")
    with pytest.raises(mergesim.ScenarioError, match="reset"):
        env.step([20.0, 0.0])


def test_unknown_planner_same_message_as_the_cli(merge_sim: str) -> None:
    """The CLI wraps the planner parser's message in clap's `invalid value ... for
    '--planner <PLANNER>': `; Python raises that message itself, from every entry point."""
    done = subprocess.run(
        [merge_sim, "run", "--planner", "pf-nope", "--no-rrd", "--quiet"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    prefix = "error: invalid value 'pf-nope' for '--planner <PLANNER>': "
    assert done.stderr.startswith(prefix), done.stderr
    expected = done.stderr[len(prefix):].splitlines()[0]
    assert expected.startswith("unknown planner 'pf-nope'")
    for call in (
        lambda: mergesim.run("urgent_merge", planner="pf-nope"),
        lambda: mergesim.sweep("urgent_merge", planners=["pf-cs", "pf-nope"], runs=1),
        lambda: mergesim.MergeEnv("urgent_merge", planner="pf-nope"),
    ):
        with pytest.raises(mergesim.ScenarioError) as raised:
            call()
        assert str(raised.value) == expected
