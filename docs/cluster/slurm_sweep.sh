#!/bin/bash
# A 10 000-run sweep of the urgent merge with PF-ISO as a Slurm job array of 16 shards.
#
#   sbatch docs/cluster/slurm_sweep.sh                 # submits the array
#   # when it is done (or chain it: sbatch --dependency=afterok:<array job id> ...):
#   merge_sim merge-results results/urgent_pf-iso_seed42/shard_*.json \
#       --json results/urgent_pf-iso_seed42/sweep.json
#
# Each task reads its shard from SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT (and
# SLURM_ARRAY_TASK_MIN, so --array=1-16 works as well as 0-15). The merged sweep.json equals,
# field for field except wall_time_s, what one `merge_sim sweep --runs 10000 --seed 42` would
# write; `cat shard_*.jsonl` (in shard order) gives its per-run rows. Any row replays alone:
#   merge_sim run --scenario urgent_merge --planner pf-iso --seed <row's seed>
#
# --resume: a task that is requeued (`scontrol requeue`) or preempted continues from the rows
# its JSONL already holds instead of starting over (on a first run there is nothing to resume).
# Slurm's time limit and scancel send SIGTERM first: the task keeps every finished row, writes
# its aggregate marked incomplete and exits 143; resubmitting it completes the shard.
#
#SBATCH --job-name=mergesim-sweep
#SBATCH --array=0-15
#SBATCH --cpus-per-task=8
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=mergesim-sweep_%A_%a.log
set -euo pipefail

OUT=${OUT:-results/urgent_pf-iso_seed42}
mkdir -p "$OUT"
merge_sim sweep \
    --scenario urgent_merge --planner pf-iso --runs 10000 --seed 42 \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --quiet \
    --json "$OUT/shard_${SLURM_ARRAY_TASK_ID}.json" \
    --jsonl "$OUT/shard_${SLURM_ARRAY_TASK_ID}.jsonl" --resume
