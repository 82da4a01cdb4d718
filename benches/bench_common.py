"""Helpers shared by the benchmark scripts in benches/: stderr logging, a command's output, and
what the machine is (CPU model, load average), for the provenance each script reports."""
from __future__ import annotations

import datetime as _dt
import os
import platform
import subprocess
import sys


def log(msg: str) -> None:
    """`msg` on stderr, at once."""
    print(msg, file=sys.stderr, flush=True)


def cmd_out(cmd: list[str], cwd: str | None = None) -> str:
    """The stripped stdout of `cmd`, or "" if it cannot run or fails."""
    try:
        return subprocess.run(cmd, cwd=cwd, check=True, capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo (else platform's guess)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
            for line in f:
                key, _, val = line.partition(":")
                if key.strip() in ("model name", "Model", "Hardware", "cpu model"):
                    return val.strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def loadavg() -> str:
    """The 1, 5 and 15 minute load averages, or "unknown"."""
    try:
        with open("/proc/loadavg", encoding="utf-8") as f:
            return " ".join(f.read().split()[:3])
    except OSError:
        return "unknown"


def provenance(root: str, binary: str, packages: dict) -> dict:
    """The run's provenance: date, machine, cores, load at start, Python, the peer's `packages`
    (name -> version), the mergesim commit (and whether the tree is dirty) and the binary's
    version and build time."""
    commit = cmd_out(["git", "rev-parse", "HEAD"], cwd=root) or "unknown"
    dirty = bool(cmd_out(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root))
    try:
        built = _dt.datetime.fromtimestamp(os.path.getmtime(binary), _dt.timezone.utc)
        built_s = built.strftime("%Y-%m-%d %H:%M:%S UTC")
    except OSError:
        built_s = "unknown"
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = None
    return {
        "date": cmd_out(["date", "-u"]) or _dt.datetime.now(_dt.timezone.utc).isoformat(),
        "machine": cmd_out(["uname", "-m"]) or platform.machine(),
        "cpu_model": cpu_model(),
        "cores": os.cpu_count(),
        "cores_usable": usable,
        "loadavg_at_start": loadavg(),
        "python": platform.python_version(),
        **packages,
        "mergesim_commit": commit,
        "mergesim_tree_dirty": dirty,
        "merge_sim_version": cmd_out([binary, "--version"]),
        "merge_sim_binary_mtime": built_s,
    }


# The [sim] periods a scenario leaves at their defaults must each be at least one physics step;
# only the safety checks' (0.01 s) can be shorter than the steps the benches use (up to 0.02 s).
DEFAULT_SAFETY_PERIOD_S = 0.01


def with_physics_step(scenario_toml: str, dt_s: float) -> str:
    """`scenario_toml` (a generated scenario with a `dt_s = ...` line in its [sim] table and no
    `safety_period_s`) with the physics step `dt_s`; where the default safety-check period would
    be shorter than one step, the checks run every step (`safety_period_s = dt_s`). Raises
    ValueError if the text does not have that form."""
    lines = scenario_toml.split("\n")
    try:
        sim = lines.index("[sim]")
    except ValueError:
        raise ValueError("the scenario has no [sim] table") from None
    if any(line.startswith("safety_period_s") for line in lines):
        raise ValueError("the scenario sets safety_period_s itself")
    for i in range(sim + 1, len(lines)):
        if lines[i].startswith("["):
            break
        if lines[i].startswith("dt_s ="):
            lines[i] = f"dt_s = {dt_s!r}"
            if dt_s > DEFAULT_SAFETY_PERIOD_S:
                lines.insert(i + 1, f"safety_period_s = {dt_s!r}")
            return "\n".join(lines)
    raise ValueError("the scenario's [sim] table has no dt_s line")


def parse_steps(text: str) -> list[float]:
    """A comma-separated list of physics steps in seconds, each within the physics world's
    range [0.0001, 0.02] s; raises ValueError naming the bad entry."""
    steps = []
    for item in text.split(","):
        try:
            dt = float(item)
        except ValueError:
            raise ValueError(f"'{item}' is not a number of seconds") from None
        if not (1e-4 <= dt <= 0.02):
            raise ValueError(f"{item} s is outside [0.0001, 0.02] s, the physics world's range")
        steps.append(dt)
    return steps
