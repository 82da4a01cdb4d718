#!/bin/bash
# Merges the shards of a sweep run by docs/cluster/slurm_sweep.sh: the aggregate OUT/sweep.json
# and the rows OUT/runs.jsonl (instance order). Chain it to the array with afterany, not afterok:
#
#   jid=$(sbatch --parsable docs/cluster/slurm_sweep.sh)
#   sbatch --dependency=afterany:$jid --export=ALL,OUT=results/mergesim_$jid \
#       docs/cluster/slurm_merge.sh
#
# afterany starts it once every task has ended, however; a task requeued before that
# (`scontrol requeue <jid>_<task>`) is waited for. It checks every shard itself: merge_sim
# merge-results refuses a missing, incomplete, duplicated or foreign shard (exit 2, naming the
# file), so a failed sweep fails here with the reason, and nothing is written. (afterok would
# never start it once any task has failed, even after the task is requeued and succeeds.) If it
# ran too early, requeue the failed tasks, then submit it again the same way.
#
# OUT is the sweep's directory; the shard count comes from OUT/sweep.env (written by the
# tasks). MERGE_SIM is the binary (default `merge_sim` on PATH).
#
#SBATCH --job-name=mergesim-merge
#SBATCH --cpus-per-task=1
#SBATCH --mem=4G
#SBATCH --time=00:30:00
#SBATCH --output=mergesim-merge_%j.log
set -euo pipefail

OUT=${OUT:?set OUT to the sweep directory (sbatch --export=ALL,OUT=results/mergesim_JOBID)}
MERGE_SIM=${MERGE_SIM:-merge_sim}
if [ ! -r "$OUT/sweep.env" ]; then
    echo "error: $OUT/sweep.env: missing: no task of the sweep started in $OUT" >&2
    exit 2
fi
SHARDS=$(sed -n 's/^SHARDS=//p' "$OUT/sweep.env")
case "$SHARDS" in
'' | *[!0-9]*)
    echo "error: $OUT/sweep.env: SHARDS = '$SHARDS' is not a shard count" >&2
    exit 2
    ;;
esac
# Every shard by name, in shard order (a glob would miss a shard that never wrote a file and
# list shard_10 before shard_2).
shards=()
for ((i = 0; i < SHARDS; i++)); do
    shards+=("$OUT/shard_$i.json")
done
echo "mergesim merge of $OUT ($SHARDS shards) on $(hostname), $("$MERGE_SIM" --version)"
"$MERGE_SIM" merge-results "${shards[@]}" --json "$OUT/sweep.json" --jsonl "$OUT/runs.jsonl"
echo "wrote $OUT/sweep.json and $OUT/runs.jsonl"
