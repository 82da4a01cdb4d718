#!/bin/bash
# One shard of a study plan (`merge_sim study`), as a task of a Slurm job array; the report is
# made by a second job once every shard has finished:
#
#   jid=$(PLAN=docs/studies/examples/urgent_merge_small.toml SHARDS=4 \
#         sbatch --parsable --array=0-3 docs/studies/slurm_study.sh)
#   PLAN=docs/studies/examples/urgent_merge_small.toml MERGE=1 \
#       sbatch --dependency=afterok:$jid docs/studies/slurm_study.sh
#
# Variables: PLAN (the plan file, readable on the nodes; its scenario path is relative to it),
# SHARDS (= the array's size, tasks numbered from 0), OUT (the report folder; default: the
# plan's `<stem>.report` beside it, on a file system every node sees), MERGE=1 (the merge job:
# checks that every run is there exactly once and writes the report), MERGE_SIM (the binary;
# default `merge_sim` on PATH), THREADS (default: the CPUs Slurm gave).
#
# Each task appends its rows to OUT/rows.shard-<task>-of-<SHARDS>.jsonl as runs finish and runs
# with --resume, so a requeued or preempted task (`scontrol requeue <jid>_<task>`) continues
# from its rows. The shard is passed explicitly (--shard TASK/SHARDS), never taken from the
# array's size. The report does not depend on SHARDS or THREADS.
#
#SBATCH --job-name=mergesim-study
#SBATCH --cpus-per-task=4
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=mergesim-study_%A_%a.log
#SBATCH --open-mode=append
set -euo pipefail

PLAN=${PLAN:?set PLAN to the study plan file}
MERGE_SIM=${MERGE_SIM:-merge_sim}
THREADS=${THREADS:-${SLURM_CPUS_PER_TASK:-1}}
out_args=()
if [ -n "${OUT:-}" ]; then
    out_args=(--out "$OUT")
fi

if ! command -v "$MERGE_SIM" >/dev/null; then
    echo "error: $MERGE_SIM not found on $(hostname): install merge_sim where the nodes see it" \
        "(docs/cluster/README.md) or set MERGE_SIM" >&2
    exit 127
fi

if [ "${MERGE:-0}" = 1 ]; then
    exec "$MERGE_SIM" study "$PLAN" "${out_args[@]}" --merge
fi

SHARDS=${SHARDS:?set SHARDS to the number of array tasks}
TASK=${SLURM_ARRAY_TASK_ID:?not a Slurm array task: submit with sbatch --array=0-$((SHARDS - 1))}
echo "mergesim study task ${SLURM_ARRAY_JOB_ID}_${TASK} on $(hostname): $PLAN," \
    "shard $TASK/$SHARDS, $THREADS threads, $("$MERGE_SIM" --version)"
exec "$MERGE_SIM" study "$PLAN" "${out_args[@]}" \
    --shard "$TASK/$SHARDS" --threads "$THREADS" --resume --quiet
