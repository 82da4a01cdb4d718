"""The fixture of the Rust inference tests (tests/data/inference_reference.json) is what scipy
and statsmodels compute today: recomputed here with the installed (pinned) libraries by
scripts/inference_reference.py, so CI checks the fixture against the libraries rather than
against itself."""

from __future__ import annotations

import importlib.util
import json
import math

import pytest

from conftest import REPO

pytest.importorskip("scipy")
pytest.importorskip("statsmodels")

SCRIPT = REPO / "scripts" / "inference_reference.py"
FIXTURE = REPO / "tests" / "data" / "inference_reference.json"


def load_script():
    spec = importlib.util.spec_from_file_location("inference_reference", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def assert_same(fresh, committed, path="$"):
    """Equal structure and strings; floats equal to 1e-12 relative (the last bits of a sum may
    differ between CPUs' vectorised code paths)."""
    if isinstance(committed, dict):
        assert isinstance(fresh, dict) and fresh.keys() == committed.keys(), path
        for key in committed:
            assert_same(fresh[key], committed[key], f"{path}.{key}")
    elif isinstance(committed, list):
        assert isinstance(fresh, list) and len(fresh) == len(committed), path
        for i, (a, b) in enumerate(zip(fresh, committed)):
            assert_same(a, b, f"{path}[{i}]")
    elif isinstance(committed, float) and not isinstance(fresh, bool) and isinstance(fresh, (int, float)):
        assert math.isclose(fresh, committed, rel_tol=1e-12, abs_tol=0.0), f"{path}: {fresh!r} != {committed!r}"
    else:
        assert fresh == committed, f"{path}: {fresh!r} != {committed!r}"


def test_fixture_is_what_scipy_and_statsmodels_compute():
    module = load_script()
    fresh = json.loads(module.render(module.compute()))
    committed = json.loads(FIXTURE.read_text())
    assert_same(fresh, committed)


def test_the_comparison_would_catch_a_changed_value():
    committed = json.loads(FIXTURE.read_text())
    changed = json.loads(FIXTURE.read_text())
    changed["mcnemar"][0]["p"] *= 1 + 1e-9
    with pytest.raises(AssertionError):
        assert_same(changed, committed)
