# %% [markdown]
# # Paired sweep: PF-SP vs PF-ISO on the urgent merge
#
# Both planners meet the same randomised instances (instance `i` has the same seed, so the same
# drawn μ, speeds and gap, for every planner), so their figures can be compared instance by
# instance: the paired difference removes the spread between instances. Run as a script
# (`python examples/paired_sweep.py [RUNS] [OUT.png]`) or cell by cell in an editor that knows
# `# %%` cells.

# %%
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import mergesim  # noqa: E402

RUNS = int(sys.argv[1]) if len(sys.argv) > 1 else 20
OUT = sys.argv[2] if len(sys.argv) > 2 else "paired_sweep.png"
BASELINE, OTHER = "pf-sp", "pf-iso"

# %% One sweep per planner over the same instances, in parallel in Rust.
rows = mergesim.sweep("urgent_merge", planners=[BASELINE, OTHER], runs=RUNS, seed=2024)
print(rows.groupby("planner")[["collisions", "near_miss", "min_gap_m", "tet_s"]].mean())

# %% Paired differences (other − baseline), instance by instance.
metrics = {
    "min_gap_m": "min gap (m)",
    "peak_yaw_rate_radps": "peak |yaw rate| of any vehicle (rad/s)",
    "min_speed_mps": "lowest speed of any vehicle (m/s)",
}
differences = {m: mergesim.paired_differences(rows, m, BASELINE, OTHER) for m in metrics}
import numpy as np  # noqa: E402


def mean_and_se(diff):
    """Mean ± standard error of the finite differences (as merge_sim sweep reports them)."""
    finite = diff[np.isfinite(diff)]
    se = finite.std(ddof=1) / len(finite) ** 0.5 if len(finite) > 1 else float("nan")
    return finite.mean(), se, len(finite)


for metric, diff in differences.items():
    mean, se, n = mean_and_se(diff)
    print(f"{metric}: mean {OTHER} − {BASELINE} = {mean:+.3g} ± {se:.2g} (n = {n}); "
          f"{OTHER} higher in {(diff > 0).sum()}, lower in {(diff < 0).sum()}")

# %% Plot: per metric, the paired difference of every instance, with the mean ± 2 SE. The y range
# is the central 90 % of the differences (widened to hold the mean's band), so one outlier does
# not flatten the rest; how many fall outside is written in the panel.
fig, axes = plt.subplots(1, len(metrics), figsize=(4.2 * len(metrics), 4))
for ax, (metric, label) in zip(axes, metrics.items()):
    diff = differences[metric]
    finite = diff[np.isfinite(diff)]
    mean, se, n = mean_and_se(diff)
    ax.axhline(0.0, color="grey", lw=0.8, ls="--")
    ax.scatter(finite.index, finite.values, s=14, alpha=0.8)
    ax.axhspan(mean - 2 * se, mean + 2 * se, color="tab:orange", alpha=0.25, label="mean ± 2 SE")
    ax.axhline(mean, color="tab:orange", lw=1.2)
    low, high = np.nanpercentile(finite, [5, 95]) if n else (0.0, 0.0)
    low, high = min(low, mean - 2 * se, 0.0), max(high, mean + 2 * se, 0.0)
    pad = 0.1 * (high - low) if high > low else 1e-6
    ax.set_ylim(low - pad, high + pad)
    outside = int(((finite < low - pad) | (finite > high + pad)).sum())
    if outside:
        ax.text(0.02, 0.02, f"{outside} outside the range shown", transform=ax.transAxes, fontsize=8)
    ax.set_xlabel("instance")
    ax.set_ylabel(f"{OTHER} − {BASELINE}")
    ax.set_title(f"{label}\nmean Δ = {mean:+.3g} ± {se:.2g} (SE)", fontsize=9)
    ax.legend(loc="best", fontsize=8)
fig.suptitle(f"urgent_merge, {RUNS} paired instances (seed 2024)")
fig.tight_layout()
fig.savefig(OUT, dpi=120)
print(f"wrote {OUT}")
