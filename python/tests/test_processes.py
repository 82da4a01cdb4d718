"""The package in other processes and under signals: a forked child (multiprocessing,
AsyncVectorEnv) after the parent simulated, and Ctrl-C during a sweep or a run."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import mergesim

from conftest import SHORT


def test_async_vector_env_after_the_parent_simulated() -> None:
    """rayon's global pool is not copied by fork; the package must not wait on it in a child."""
    script = textwrap.dedent(
        """
        import gymnasium as gym
        import mergesim
        short = {"sim": {"duration_s": 2.0}}
        mergesim.run("urgent_merge", seed=1, params=short)
        env = mergesim.MergeEnv(params=short)
        env.reset(seed=1)
        env.step([20.0, -3.5])
        vector = gym.vector.AsyncVectorEnv(
            [lambda: mergesim.MergeEnv(params=short) for _ in range(2)], context="fork"
        )
        vector.reset(seed=0)
        vector.step(vector.action_space.sample())
        vector.close()
        print("ok")
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().endswith("ok")


def _interrupt_after(seconds: float) -> threading.Timer:
    # Python's own Ctrl-C handler, whatever this process inherited: a shell without job control
    # starts background commands with SIGINT ignored, and Python then installs no handler.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_a_sweep() -> None:
    started = time.monotonic()
    timer = _interrupt_after(1.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            # Minutes of work without the interrupt.
            mergesim.sweep("urgent_merge", planners=["pf-cs", "pf-iso"], runs=2000, seed=3)
    finally:
        timer.cancel()
    assert time.monotonic() - started < 30.0


def test_ctrl_c_stops_a_run() -> None:
    started = time.monotonic()
    timer = _interrupt_after(1.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            mergesim.run("platoon_merge_50")
    finally:
        timer.cancel()
    assert time.monotonic() - started < 30.0
    # The package still works afterwards.
    assert mergesim.run("urgent_merge", params=SHORT).summary["collisions"] == 0
