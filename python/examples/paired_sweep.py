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
for metric, diff in differences.items():
    se = diff.std(ddof=1) / len(diff) ** 0.5 if len(diff) > 1 else float("nan")
    print(f"{metric}: mean {OTHER} − {BASELINE} = {diff.mean():+.3f} ± {se:.3f} (n = {len(diff)})")

# %% Plot: per metric, the baseline against the other planner, one point per instance.
fig, axes = plt.subplots(1, len(metrics), figsize=(4.2 * len(metrics), 4))
done = rows[rows["status"] == "completed"]
for ax, (metric, label) in zip(axes, metrics.items()):
    table = done.pivot(index="instance", columns="planner", values=metric).astype(float).dropna()
    ax.scatter(table[BASELINE], table[OTHER], s=14, alpha=0.8)
    low = min(table[BASELINE].min(), table[OTHER].min())
    high = max(table[BASELINE].max(), table[OTHER].max())
    ax.plot([low, high], [low, high], color="grey", lw=0.8, ls="--")
    ax.set_xlabel(f"{BASELINE}")
    ax.set_ylabel(f"{OTHER}")
    ax.set_title(f"{label}\nmean Δ = {differences[metric].mean():+.3f}", fontsize=9)
fig.suptitle(f"urgent_merge, {RUNS} paired instances (seed 2024)")
fig.tight_layout()
fig.savefig(OUT, dpi=120)
print(f"wrote {OUT}")
