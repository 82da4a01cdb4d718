"""Shared fixtures: short runs (CI has 2 cores) and the merge_sim binary to compare with."""

from __future__ import annotations

import os
import pathlib
import shutil
from typing import Optional

import pytest

#: Every test simulates at most a few seconds.
SHORT = {"sim": {"duration_s": 2.0}}

REPO = pathlib.Path(__file__).resolve().parents[2]


def merge_sim_binary() -> Optional[str]:
    """The CLI built by `cargo test --release --workspace` (or MERGESIM_BIN, or on PATH)."""
    candidates = [os.environ.get("MERGESIM_BIN"), str(REPO / "target" / "release" / "merge_sim")]
    for candidate in candidates:
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("merge_sim")


@pytest.fixture
def merge_sim() -> str:
    binary = merge_sim_binary()
    if binary is None:
        # A failure, not a skip: these comparisons are the point of the tests.
        pytest.fail("merge_sim not found: build it (cargo build --release) or set MERGESIM_BIN")
    return binary


@pytest.fixture
def short_urgent_merge(tmp_path: pathlib.Path) -> pathlib.Path:
    """urgent_merge with a 2 s duration, as a file both the CLI and Python can read."""
    import mergesim._native as native  # noqa: F401  (the package must import)

    text = (REPO / "scenarios" / "builtin" / "urgent_merge.toml").read_text()
    assert "duration_s = 25.0" in text, "urgent_merge.toml no longer says duration_s = 25.0"
    text = text.replace("duration_s = 25.0", "duration_s = 2.0")
    path = tmp_path / "short.toml"
    path.write_text(text)
    return path
