#!/usr/bin/env python3
"""Paired wall-time comparison of two commands on a shared (loaded) machine.

Runs command A and command B alternately, PAIRS times, swapping which goes first in every
other pair (AB, BA, AB, ...), so a load that drifts over minutes affects both alike. Prints the
time of each run, the median of each command, and the median and range of the per-pair ratio
B/A (the figure to quote: a pair's two runs are seconds apart).

    scripts/paired_timing.py --pairs 8 -- OLD_BINARY run --scenario urgent_merge \
        -- NEW_BINARY run --scenario urgent_merge

The commands' output goes to /dev/null; a command that fails stops the comparison (exit 2).
"""

import argparse
import statistics
import subprocess
import sys
import time


def run(cmd):
    start = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        sys.stderr.write(
            f"error: {' '.join(cmd)} exited with {done.returncode}:\n"
            + done.stderr.decode(errors="replace")
        )
        sys.exit(2)
    return elapsed


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", type=int, default=8, help="number of A/B pairs (default 8)")
    parser.add_argument("commands", nargs=argparse.REMAINDER, help="-- A ... -- B ...")
    args = parser.parse_args()
    words = args.commands
    if words.count("--") != 2 or words[0] != "--":
        parser.error("give the two commands as: -- A ... -- B ...")
    split = words.index("--", 1)
    a, b = words[1:split], words[split + 1 :]
    if not a or not b or args.pairs < 1:
        parser.error("two non-empty commands and at least one pair are needed")
    times_a, times_b, ratios = [], [], []
    for k in range(args.pairs):
        if k % 2 == 0:
            ta, tb = run(a), run(b)
        else:
            tb, ta = run(b), run(a)
        times_a.append(ta)
        times_b.append(tb)
        ratios.append(tb / ta)
        print(f"pair {k + 1}: A {ta:.3f} s, B {tb:.3f} s, B/A {tb / ta:.3f}", flush=True)
    print(
        f"A median {statistics.median(times_a):.3f} s, B median {statistics.median(times_b):.3f} s; "
        f"B/A per pair: median {statistics.median(ratios):.3f} "
        f"(min {min(ratios):.3f}, max {max(ratios):.3f}, {args.pairs} pairs)"
    )


if __name__ == "__main__":
    main()
