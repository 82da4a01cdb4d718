"""examples/paired_sweep.py runs and writes its figure (with 2 instances)."""

from __future__ import annotations

import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "paired_sweep.py"


def test_paired_sweep_example(tmp_path: pathlib.Path) -> None:
    out = tmp_path / "paired.png"
    subprocess.run([sys.executable, str(EXAMPLE), "2", str(out)], check=True, cwd=tmp_path)
    assert out.stat().st_size > 10_000
