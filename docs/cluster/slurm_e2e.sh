#!/bin/bash
# End-to-end test of the documented Slurm workflow (docs/cluster/README.md) on a throw-away
# single-node Slurm: installs Debian's slurm-wlm and munge if missing, starts munged, slurmctld
# and slurmd by hand (no systemd) with a generated slurm.conf for this host, then
#
#  1. submits docs/cluster/slurm_sweep.sh as an array of SHARDS tasks and docs/cluster/
#     slurm_merge.sh chained to it with afterany, exactly as documented;
#  2. makes one task fail for real (its --json path is a directory: merge_sim exits 2), checks
#     that the merge job keeps waiting, removes the cause and requeues the task
#     (`scontrol requeue JOBID_TASK`), and lets the merge job run;
#  3. checks the merged sweep.json against an unsharded `merge_sim sweep` (every field but the
#     wall times), runs.jsonl against its rows sorted by instance (every field but wall_time_s,
#     which the merge leaves null), and the merged wall_time_s as the shards' sum;
#  4. resubmits one task the "obvious" way (`sbatch --array=N`, OUT given) and checks it runs
#     shard N/SHARDS (and has nothing left to run), and that a resubmission without the shard
#     count is refused;
#
# printing what it does; it exits non-zero on any mismatch. Run it as root on Debian or Ubuntu:
#
#   docs/cluster/slurm_e2e.sh                # builds merge_sim with cargo (release)
#   MERGE_SIM=/path/to/merge_sim docs/cluster/slurm_e2e.sh
#
# Variables: MERGE_SIM, SHARDS (default 12: shard_10 and shard_11 sort before shard_2 in a
# glob), RUNS (24), SEED (42), PLANNERS (pf-iso; e.g. pf-cs,pf-iso for a paired sweep),
# FAIL_TASK (3), WORK (a new directory under /tmp), KEEP=1 to keep WORK. To keep the test
# deterministic on 2 CPUs the array is submitted held and the failing task released first
# (`sbatch --hold`, `scontrol release`); nothing else differs from the documented commands.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
SHARDS=${SHARDS:-12}
RUNS=${RUNS:-24}
SEED=${SEED:-42}
SCENARIO=${SCENARIO:-urgent_merge}
PLANNERS=${PLANNERS:-pf-iso}
FAIL_TASK=${FAIL_TASK:-3}
RESUBMIT_TASK=$(((FAIL_TASK + 2) % SHARDS))
WORK=${WORK:-$(mktemp -d /tmp/mergesim_slurm_e2e.XXXXXX)}
START=$(date +%s)

say() { echo "[$(($(date +%s) - START)) s] $*"; }
fail() {
    echo "E2E FAILED: $*" >&2
    exit 1
}

say "mergesim Slurm end-to-end test, $(date -u '+%Y-%m-%d %H:%M UTC') on $(hostname)," \
    "work directory $WORK"
[ "$(id -u)" = 0 ] || fail "run as root: it installs packages and starts munged, slurmctld, slurmd"

# --- Slurm and munge -----------------------------------------------------------------------
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
    ! command -v munged >/dev/null || ! command -v jq >/dev/null; then
    say "installing slurm-wlm, munge and jq (apt-get)"
    t0=$(date +%s)
    DEBIAN_FRONTEND=noninteractive apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge jq >/dev/null
    say "installed in $(($(date +%s) - t0)) s: $(slurmctld -V)"
else
    say "already installed: $(slurmctld -V), $(munged --version 2>&1 | head -1)"
fi

# --- merge_sim, installed into a prefix the tasks find on PATH ----------------------------
mkdir -p "$WORK/prefix/bin" "$WORK/submit"
if [ -n "${MERGE_SIM:-}" ]; then
    cp "$MERGE_SIM" "$WORK/prefix/bin/merge_sim"
else
    say "building merge_sim (cargo build --release --bin merge_sim)"
    (cd "$repo" && cargo build --release --bin merge_sim)
    cp "${CARGO_TARGET_DIR:-$repo/target}/release/merge_sim" "$WORK/prefix/bin/merge_sim"
fi
export PATH="$WORK/prefix/bin:$PATH"
unset MERGE_SIM # the tasks find merge_sim on PATH, as documented
needs=$(grep -ao 'GLIBC_2\.[0-9]*' "$WORK/prefix/bin/merge_sim" | sort -uV | tail -1)
say "merge_sim: $(merge_sim --version) in $WORK/prefix/bin (on PATH, passed on by sbatch's" \
    "default --export=ALL); it needs $needs, this node has $(ldd --version | head -1)"

# --- munged, slurmctld, slurmd ---------------------------------------------------------------
started=()
cleanup() {
    local pid
    for pid in "${started[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    # The daemons write their state as they stop: wait for them before removing it.
    for pid in "${started[@]}"; do
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.2
        done
    done
    if [ "${KEEP:-0}" != 1 ]; then
        rm -rf "$WORK" || echo "warning: could not remove all of $WORK" >&2
    fi
}
trap cleanup EXIT
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    mkdir -p /run/munge
    chown munge:munge /run/munge
    runuser -u munge -- /usr/sbin/munged
    sleep 1
    started+=("$(cat /run/munge/munged.pid)")
    say "started munged (pid ${started[-1]})"
fi
node=$(hostname -s)
conf="$WORK/slurm"
mkdir -p "$conf/state" "$conf/spool" "$conf/log"
cat >"$conf/slurm.conf" <<EOF
# A one-node cluster for the end-to-end test, made by docs/cluster/slurm_e2e.sh.
ClusterName=mergesim-e2e
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$conf/state
SlurmdSpoolDir=$conf/spool
SlurmctldPidFile=$conf/slurmctld.pid
SlurmdPidFile=$conf/slurmd.pid
SlurmctldLogFile=$conf/log/slurmctld.log
SlurmdLogFile=$conf/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
MinJobAge=3600
NodeName=$node CPUs=2 RealMemory=2000 State=UNKNOWN
PartitionName=e2e Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$conf/slurm.conf"
slurmctld -f "$SLURM_CONF"
sleep 1
started+=("$(cat "$conf/slurmctld.pid")")
slurmd -f "$SLURM_CONF"
sleep 1
started+=("$(cat "$conf/slurmd.pid")")
for _ in $(seq 30); do
    [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break
    sleep 1
done
[ "$(sinfo -h -o %T)" = idle ] || fail "the node did not come up: $(sinfo)"
say "slurmctld and slurmd up ($SLURM_CONF): $(sinfo -h -o '%P %D node(s) %c CPUs %T')"

# State of a job or array task (FAILED, COMPLETED, PENDING, ...).
state() { scontrol show job -o "$1" | grep -o 'JobState=[A-Z_]*' | head -1 | cut -d= -f2; }
# Waits until job $1 reaches one of the states $2 (a regex), for at most 600 s.
wait_for() {
    local s
    for _ in $(seq 600); do
        s=$(state "$1")
        [[ $s =~ ^($2)$ ]] && return 0
        sleep 1
    done
    fail "job $1 is $s after 600 s, expected $2"
}

# --- 1. the documented submission --------------------------------------------------------------
OUT="$WORK/results/sweep"
mkdir -p "$OUT/shard_$FAIL_TASK.json" # the provoked failure: an output that is a directory
cd "$WORK/submit"
# The settings go through the environment (sbatch's default --export=ALL), not an --export
# list: Slurm splits that at commas, so PLANNERS=pf-cs,pf-iso would arrive as PLANNERS=pf-cs.
with_settings() {
    env SCENARIO="$SCENARIO" PLANNERS="$PLANNERS" RUNS="$RUNS" SEED="$SEED" SHARDS="$SHARDS" \
        OUT="$OUT" "$@"
}
jid=$(with_settings sbatch --parsable --hold --array="0-$((SHARDS - 1))" --cpus-per-task=1 \
    --mem=200M "$repo/docs/cluster/slurm_sweep.sh")
mid=$(sbatch --parsable --dependency="afterany:$jid" --mem=200M --export="ALL,OUT=$OUT" \
    "$repo/docs/cluster/slurm_merge.sh")
say "submitted the sweep as array job $jid (tasks 0-$((SHARDS - 1)): $RUNS runs of $SCENARIO" \
    "with $PLANNERS, seed $SEED, in $SHARDS shards, OUT=$OUT) and the merge as job $mid" \
    "(--dependency=afterany:$jid)"

# --- 2. a task fails, is requeued, the merge waits for it -------------------------------------
scontrol release "${jid}_$FAIL_TASK"
wait_for "${jid}_$FAIL_TASK" 'FAILED|COMPLETED'
[ "$(state "${jid}_$FAIL_TASK")" = FAILED ] || fail "task $FAIL_TASK did not fail"
log="mergesim-sweep_${jid}_$FAIL_TASK.log"
say "task $FAIL_TASK failed as provoked; its log $log:"
sed 's/^/    /' "$log"
grep -q "shard $FAIL_TASK/$SHARDS," "$log" || fail "no task banner in $log"
grep -q "not a regular file\|directory" "$log" || fail "$log does not name the cause"
[ "$(state "$mid")" = PENDING ] || fail "the merge job is $(state "$mid"), not waiting"
say "the merge job $mid is still pending: $(scontrol show job -o "$mid" | grep -o 'Dependency=[^ ]*')"
rmdir "$OUT/shard_$FAIL_TASK.json"
scontrol requeue "${jid}_$FAIL_TASK"
# A requeued job becomes eligible only after Slurm's requeue delay (about 2 min); skip it.
scontrol update JobId="${jid}_$FAIL_TASK" StartTime=now
say "removed the cause, ran: scontrol requeue ${jid}_$FAIL_TASK (and StartTime=now)"
scontrol release "$jid"
say "released the other tasks; waiting for the merge job"
wait_for "$mid" 'COMPLETED|FAILED|CANCELLED|TIMEOUT|OUT_OF_MEMORY'
say "merge job $mid ended $(state "$mid"); its log:"
sed 's/^/    /' "mergesim-merge_$mid.log"
[ "$(state "$mid")" = COMPLETED ] || fail "the merge job did not complete"
for ((i = 0; i < SHARDS; i++)); do
    s=$(state "${jid}_$i")
    [ "$s" = COMPLETED ] || fail "task $i is $s"
    grep -q "shard $i/$SHARDS = instances" "mergesim-sweep_${jid}_$i.log" ||
        fail "no banner in the log of task $i"
done
say "all $SHARDS tasks COMPLETED (task $FAIL_TASK after one requeue: $(scontrol show job -o \
    "${jid}_$FAIL_TASK" | grep -o 'Restarts=[0-9]*')), each log with its banner, e.g.:"
sed 's/^/    /' "mergesim-sweep_${jid}_$((SHARDS - 1)).log"
say "task $FAIL_TASK's log, both attempts (--open-mode=append):"
sed 's/^/    /' "$log"

# --- 3. the merged results equal an unsharded sweep's -------------------------------------------
say "running the same sweep unsharded: merge_sim sweep --scenario $SCENARIO --planners" \
    "$PLANNERS --runs $RUNS --seed $SEED"
merge_sim sweep --scenario "$SCENARIO" --planners "$PLANNERS" --runs "$RUNS" --seed "$SEED" \
    --quiet --json "$WORK/whole.json" --jsonl "$WORK/whole.jsonl"
no_walls='walk(if type == "object" then del(.wall_time_s) else . end)'
diff <(jq -S "$no_walls" "$WORK/whole.json") <(jq -S "$no_walls" "$OUT/sweep.json") >/dev/null ||
    fail "sweep.json differs from the unsharded aggregate"
say "sweep.json equals the unsharded aggregate in every field but wall_time_s:" \
    "$(jq -c 'def figures: {planner, runs, collisions, near_misses, min_gap_m_p5,
        mean_peak_yaw_rate_radps}; if .per_planner then [.per_planner[] | figures] else figures
        end' "$OUT/sweep.json")"
# The unsharded rows (completion order) sorted by instance, then the sweep's planner order.
sorted='sort_by(.instance, (.planner as $p | .planners | index($p))) | .[] | del(.wall_time_s)'
jq -s -c "$sorted" "$WORK/whole.jsonl" >"$WORK/whole.sorted"
jq -c 'del(.wall_time_s)' "$OUT/runs.jsonl" >"$WORK/merged.rows"
rows=$(wc -l <"$WORK/merged.rows")
cmp -s "$WORK/whole.sorted" "$WORK/merged.rows" ||
    fail "runs.jsonl differs from the unsharded rows in instance order: $(diff \
        "$WORK/whole.sorted" "$WORK/merged.rows" | head -c 600)"
[ "$(jq -s 'map(select(.wall_time_s != null)) | length' "$OUT/runs.jsonl")" = 0 ] ||
    fail "runs.jsonl has per-run wall times"
say "runs.jsonl: $rows rows, equal to the unsharded rows in (instance, planner) order (instances" \
    "$(jq -r -s '[.[].instance] | "\(first)..\(last)"' "$OUT/runs.jsonl"))"
glob_order=$(cd "$OUT" && echo shard_*.jsonl)
say "(a glob lists the shards as: $glob_order)"
shard_list=()
for ((i = 0; i < SHARDS; i++)); do shard_list+=("$OUT/shard_$i.json"); done
sum=$(jq -s 'map(.wall_time_s) | add' "${shard_list[@]}")
merged=$(jq '.wall_time_s' "$OUT/sweep.json")
jq -n --argjson a "$sum" --argjson b "$merged" '($a - $b | fabs) <= 1e-9 * ($a + 1)' | grep -q true ||
    fail "wall_time_s $merged is not the shards' sum $sum"
say "the merged wall_time_s $merged s is the sum of the shards' (the array's elapsed time" \
    "was shorter: the tasks ran 2 at a time)"

# --- 4. resubmitting one task -------------------------------------------------------------------
rid=$(with_settings sbatch --parsable --array="$RESUBMIT_TASK" --cpus-per-task=1 --mem=200M \
    "$repo/docs/cluster/slurm_sweep.sh")
wait_for "$rid" 'COMPLETED|FAILED|CANCELLED'
rlog="mergesim-sweep_${rid}_$RESUBMIT_TASK.log"
say "resubmitted task $RESUBMIT_TASK alone (sbatch --array=$RESUBMIT_TASK, OUT given): job $rid" \
    "$(state "$rid"); its log:"
sed 's/^/    /' "$rlog"
[ "$(state "$rid")" = COMPLETED ] || fail "the resubmitted task failed"
grep -q "shard $RESUBMIT_TASK/$SHARDS = instances" "$rlog" || fail "wrong shard in $rlog"
grep -q "0 to run" "$rlog" || fail "the resubmitted task ran its shard again"
bad=$(with_settings env -u SHARDS sbatch --parsable --array="$RESUBMIT_TASK" --cpus-per-task=1 \
    --mem=200M "$repo/docs/cluster/slurm_sweep.sh")
wait_for "$bad" 'COMPLETED|FAILED|CANCELLED'
say "resubmitted it without SHARDS (the default 16): job $bad $(state "$bad"); its log:"
sed 's/^/    /' "mergesim-sweep_${bad}_$RESUBMIT_TASK.log"
[ "$(state "$bad")" = FAILED ] || fail "a resubmission with the wrong shard count ran"
merge_sim merge-results --quiet "${shard_list[@]}" --jsonl "$WORK/again.jsonl"
cmp -s "$WORK/again.jsonl" "$OUT/runs.jsonl" || fail "the rows changed after the resubmission"
say "merging again gives the same runs.jsonl, byte for byte"

say "PASSED: $SHARDS shards, $rows rows, in $(($(date +%s) - START)) s"
