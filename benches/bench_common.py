"""Helpers shared by the benchmark scripts in benches/: stderr logging, a command's output, and
what the machine is (CPU model, load average), for the provenance each script reports."""
from __future__ import annotations

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
