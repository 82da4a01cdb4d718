#!/bin/bash
# One shard of a seeded Monte-Carlo sweep, as a task of a Slurm job array. By default: 10 000
# runs of urgent_merge with PF-ISO, seed 42, in 16 shards (tasks 0-15, 4 CPUs each). Every
# setting is a variable of the environment sbatch passes on (see docs/cluster/README.md):
#
#   jid=$(sbatch --parsable docs/cluster/slurm_sweep.sh)
#   sbatch --dependency=afterany:$jid --export=ALL,OUT=results/mergesim_$jid \
#       docs/cluster/slurm_merge.sh
#
#   # another sweep: SHARDS must equal the number of tasks, numbered from 0
#   RUNS=2000 SEED=7 PLANNERS=pf-cs,pf-iso SHARDS=8 sbatch --array=0-7 docs/cluster/slurm_sweep.sh
#
# Variables: SCENARIO (a built-in name or a TOML path readable on the nodes), PLANNERS (one, or
# several separated by commas or colons: a paired sweep; in an sbatch --export list, which Slurm
# splits at commas, write PLANNERS=pf-cs:pf-iso), RUNS, SEED, SHARDS (= the array's size), OUT (the
# sweep's directory; default results/mergesim_<array job id>, so every sweep gets its own),
# MERGE_SIM (the binary; default `merge_sim` on PATH), THREADS (default: the CPUs Slurm gave).
#
# The shard is passed explicitly (--shard TASK/SHARDS), never taken from the array's size: a
# task run again alone is an array of one task. A failed task is best run again with
#   scontrol requeue <array job id>_<task>
# (same job id, so the same OUT; the merge job chained with afterany waits for it if the other
# tasks are still running, else submit the merge again). Resubmitting it also works if OUT and
# the sweep's settings are given: OUT=results/mergesim_<jid> SHARDS=16 sbatch --array=3 ...;
# settings that differ from the sweep recorded in OUT/sweep.env are refused.
# --resume makes a requeued or preempted task continue from the rows its JSONL holds. Slurm's
# time limit and scancel send SIGTERM first: the task keeps every finished row and exits 143.
# The log is appended to (--open-mode=append), so a requeued task's log keeps the failure.
# --cpus-per-task: a request larger than any node of the partition may pend for ever without an
# error (compare with `sinfo -o '%n %c %m'`); override it with sbatch -c N.
#
# merge_sim must run on the compute nodes: install it where they see it (docs/cluster/README.md:
# `cargo install --path . --bin merge_sim --root /shared/prefix`, a glibc on the nodes at least
# that of the build machine) and have it on PATH (sbatch passes the submitting shell's PATH
# unless --export=NONE) or set MERGE_SIM to its full path.
#
#SBATCH --job-name=mergesim-sweep
#SBATCH --array=0-15
#SBATCH --cpus-per-task=4
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --output=mergesim-sweep_%A_%a.log
#SBATCH --open-mode=append
set -euo pipefail

SCENARIO=${SCENARIO:-urgent_merge}
PLANNERS=${PLANNERS:-pf-iso}
PLANNERS=${PLANNERS//:/,}
RUNS=${RUNS:-10000}
SEED=${SEED:-42}
SHARDS=${SHARDS:-16}
MERGE_SIM=${MERGE_SIM:-merge_sim}
THREADS=${THREADS:-${SLURM_CPUS_PER_TASK:-1}}
TASK=${SLURM_ARRAY_TASK_ID:?not a Slurm array task: submit with sbatch --array=0-$((SHARDS - 1))}
OUT=${OUT:-results/mergesim_${SLURM_ARRAY_JOB_ID}}

if ! command -v "$MERGE_SIM" >/dev/null; then
    echo "error: $MERGE_SIM not found on $(hostname) (PATH=$PATH): install merge_sim where the" \
        "nodes see it and put it on PATH, or set MERGE_SIM (docs/cluster/README.md)" >&2
    exit 127
fi
# The job log says what ran, even though merge_sim runs with --quiet (it prints its one-line
# shard banner to stderr as well).
echo "mergesim task ${SLURM_ARRAY_JOB_ID}_${TASK} on $(hostname): $SCENARIO $PLANNERS," \
    "runs $RUNS, seed $SEED, shard $TASK/$SHARDS, $THREADS threads, OUT=$OUT," \
    "$("$MERGE_SIM" --version)"
if [ "${SLURM_ARRAY_TASK_COUNT:-$SHARDS}" != "$SHARDS" ]; then
    echo "note: this array has ${SLURM_ARRAY_TASK_COUNT} task(s) but SHARDS=$SHARDS: this task" \
        "runs shard $TASK/$SHARDS (right for a task of a $SHARDS-shard sweep run again alone)"
fi

mkdir -p "$OUT"
# What the sweep in OUT is: refuse to mix the shards of two sweeps in one directory.
identity="SCENARIO=$SCENARIO
PLANNERS=$PLANNERS
RUNS=$RUNS
SEED=$SEED
SHARDS=$SHARDS"
if [ -e "$OUT/sweep.env" ]; then
    if [ "$(cat "$OUT/sweep.env")" != "$identity" ]; then
        {
            echo "error: $OUT/sweep.env holds another sweep:"
            sed 's/^/    /' "$OUT/sweep.env"
            echo "but this task is:"
            printf '%s\n' "$identity" | sed 's/^/    /'
            echo "run this task with the settings of the sweep in OUT (e.g. SHARDS), or choose" \
                "another OUT for a new sweep"
        } >&2
        exit 2
    fi
else
    printf '%s\n' "$identity" >"$OUT/sweep.env.$TASK.tmp"
    mv -f "$OUT/sweep.env.$TASK.tmp" "$OUT/sweep.env"
fi

exec "$MERGE_SIM" sweep \
    --scenario "$SCENARIO" --planners "$PLANNERS" --runs "$RUNS" --seed "$SEED" \
    --shard "$TASK/$SHARDS" --threads "$THREADS" --quiet \
    --json "$OUT/shard_$TASK.json" --jsonl "$OUT/shard_$TASK.jsonl" --resume
