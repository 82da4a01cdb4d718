"""The fixture of the Rust CommonRoad-model tests (tests/data/commonroad_models/reference.json)
is what commonroad-vehicle-models 3.0.2 computes today: recomputed here by
scripts/commonroad_models_reference.py with the installed package, so that the fixture is
checked against the package rather than against itself. The package comes with commonroad-io
(python/ci.sh pins commonroad-io, which requires commonroad-vehicle-models >= 2.0.0); skipped
where it is missing or another version than the fixture's 3.0.2
(`pip install commonroad-vehicle-models==3.0.2`)."""

from __future__ import annotations

import importlib.util
import json
import math
from importlib import metadata

import pytest

from conftest import REPO

pytest.importorskip("vehiclemodels")
if metadata.version("commonroad-vehicle-models") != "3.0.2":
    pytest.skip("the fixture is for commonroad-vehicle-models 3.0.2", allow_module_level=True)

SCRIPT = REPO / "scripts" / "commonroad_models_reference.py"
FIXTURE = REPO / "tests" / "data" / "commonroad_models" / "reference.json"


def load_script():
    spec = importlib.util.spec_from_file_location("commonroad_models_reference", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def assert_same(fresh, committed, path="$"):
    """Equal structure and strings; floats equal to 1e-9 relative, or 1e-12 absolute near 0 (the
    trajectories go through the C maths library, whose last bits may differ between builds)."""
    if isinstance(committed, dict):
        assert isinstance(fresh, dict) and fresh.keys() == committed.keys(), path
        for key in committed:
            assert_same(fresh[key], committed[key], f"{path}.{key}")
    elif isinstance(committed, list):
        assert isinstance(fresh, list) and len(fresh) == len(committed), path
        for i, (a, b) in enumerate(zip(fresh, committed)):
            assert_same(a, b, f"{path}[{i}]")
    elif isinstance(committed, float) and not isinstance(fresh, bool) and isinstance(fresh, (int, float)):
        assert math.isclose(fresh, committed, rel_tol=1e-9, abs_tol=1e-12), f"{path}: {fresh!r} != {committed!r}"
    else:
        assert fresh == committed, f"{path}: {fresh!r} != {committed!r}"


def test_fixture_is_what_the_package_computes():
    module = load_script()
    fresh = json.loads(json.dumps(module.build()))
    committed = json.loads(FIXTURE.read_text())
    assert_same(fresh, committed)


def test_the_comparison_would_catch_a_changed_value():
    committed = json.loads(FIXTURE.read_text())
    changed = json.loads(FIXTURE.read_text())
    changed["manoeuvres"][0]["states"][-1][0] *= 1 + 1e-6
    with pytest.raises(AssertionError):
        assert_same(changed, committed)
