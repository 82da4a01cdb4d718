#!/usr/bin/env bash
# Side-by-side throughput: simulated vehicle-seconds per wall-clock second of mergesim and of
# highway-env's merge-v0, measured in one run on this machine, paired and interleaved
# (highway-env, mergesim, mergesim PF-CS, highway-env, ...), one untimed warm-up of each first.
# Prints a Markdown table on stdout (progress on stderr); --json PATH also writes every sample.
#
# What each side simulates -- they are not the same model, and this is a throughput comparison,
# not a like-for-like one:
#   * mergesim (`merge_sim run --scenario urgent_merge --no-rrd --json OUT --quiet`, PF-ISO by
#     default): Rapier rigid-body vehicles stepped at 500 Hz with tire forces, each vehicle
#     re-planning at 10 Hz with a potential-field planner and Clarabel QPs (speed optimisation),
#     plus V2V, tracking, safety metrics and the JSON summary. The paper's urgent merge has 2
#     vehicles for 25 s = 50 vehicle-seconds per run. A second row runs `--planner pf-cs` (the
#     cheaper planner) so the cost of planning shows.
#   * highway-env merge-v0 (default config: kinematic bicycle vehicles at simulation_frequency
#     15 Hz, policy_frequency 1 Hz, other vehicles IDM longitudinal + MOBIL lane changes, Kinematics
#     observation, DiscreteMetaAction), render_mode=None, ego held on the constant IDLE action.
#     5 vehicles (len(env.unwrapped.road.vehicles); the static obstacle at the end of the ramp is
#     a road object, not counted). Episodes run to termination (ego crash or ego x > 370 m;
#     merge-v0 has no time limit; a 1000-policy-step safety cap is reported if it ever triggers).
#     With IDLE the ego (MDPVehicle) holds 30 m/s without reacting and runs into a slower car:
#     with seeds 0..9 every episode ends in that crash after 4-8 s, so env.reset() runs every
#     ~5.6 simulated s (its cost is in the main column, not in the steps-only one). One repetition =
#     --hwe-episodes episodes (default 10, seeds 0..9, identical in every repetition).
#     Vehicle-seconds = len(road.vehicles) summed over every simulation step x 1/15 s.
# What is timed:
#   * mergesim: the wall time of the whole `merge_sim` process measured here around the
#     subprocess -- process start-up, scenario parsing and JSON writing INCLUDED (conservative
#     for mergesim); the JSON's in-process `wall_time_s` is the second column.
#   * highway-env: only env.reset() and env.step() calls -- Python start-up, package import and
#     gym.make are EXCLUDED (favourable to highway-env); steps-only is the second column. The
#     observation, reward and info that env.step() computes each policy step are included: that
#     is what a highway-env user pays.
# The machine is shared: run it on a quiet machine and read the min-max spread.
#
# Setup: a venv in $MERGESIM_BENCH_VENV (default target/bench-venv, git-ignored with target/),
# created with `python3 -m venv` if missing, into which pip installs the pinned versions below
# if they are not there (pinned: highway-env==1.12.1 with gymnasium==1.4.0, the versions this
# script was written and run against; numpy is whatever pip resolves, and is reported). The
# merge_sim binary is built (`cargo build --release --bin merge_sim`) if missing, or always with
# --build. Needs bash, python3 (with venv/ensurepip), pip access to PyPI, cargo.
#
# Usage: benches/compare_highway_env.sh [--reps N] [--scenario NAME] [--planner NAME] [--vehicle-model M] [--dt-s DT,...]
#                                       [--hwe-episodes N] [--json PATH] [--build] [--help]
set -euo pipefail

HIGHWAY_ENV_PIN="highway-env==1.12.1"
GYMNASIUM_PIN="gymnasium==1.4.0"

usage() {
  cat <<'EOF'
Usage: benches/compare_highway_env.sh [OPTIONS]

Simulated vehicle-seconds per wall-clock second: mergesim (`merge_sim run --no-rrd`, plus a
`--planner pf-cs` row) vs highway-env merge-v0 (IDLE ego), interleaved and paired in one run.
Markdown table on stdout. See the header of this script for what is simulated and timed.

Options:
  --reps N           repetitions of each variant, interleaved (default 5)
  --scenario NAME    mergesim scenario, built-in name or TOML path (default urgent_merge)
  --planner NAME     planner for the main mergesim row (passed to `merge_sim run --planner`;
                     default: the scenario's own, PF-ISO for urgent_merge)
  --vehicle-model M  vehicle model of every mergesim car (`merge_sim run --vehicle-model`:
                     rapier, the default, ks, st or std)
  --dt-s DT[,DT...]  physics step(s) of the mergesim runs (s): one row per value (and its PF-CS
                     row), each from a copy of the scenario with [sim] dt_s replaced (default: the
                     scenario's own, 0.002 for the built-ins); e.g. 0.002,0.01 with ks vehicles
  --hwe-episodes N   highway-env episodes per repetition (default 10)
  --json PATH        also write all samples and the environment as JSON
  --build            run `cargo build --release --bin merge_sim` even if the binary exists
  -h, --help         this help

Environment:
  MERGESIM_BENCH_VENV  venv directory (default target/bench-venv in the checkout)
EOF
}

reps=5
scenario=urgent_merge
planner=""
vehicle_model=""
dt_s=""
hwe_episodes=10
json=""
build=0
need() { [[ $# -ge 2 && -n $2 ]] || { echo "error: $1 needs a value" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
  case $1 in
    --reps) need "$@"; reps=$2; shift 2 ;;
    --scenario) need "$@"; scenario=$2; shift 2 ;;
    --planner) need "$@"; planner=$2; shift 2 ;;
    --vehicle-model) need "$@"; vehicle_model=$2; shift 2 ;;
    --dt-s) need "$@"; dt_s=$2; shift 2 ;;
    --hwe-episodes) need "$@"; hwe_episodes=$2; shift 2 ;;
    --json) need "$@"; json=$2; shift 2 ;;
    --build) build=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "error: unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ $reps =~ ^[1-9][0-9]*$ ]] || { echo "error: --reps must be a positive integer" >&2; exit 2; }
[[ $hwe_episodes =~ ^[1-9][0-9]*$ ]] || { echo "error: --hwe-episodes must be a positive integer" >&2; exit 2; }

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/target/release/merge_sim"
venv=${MERGESIM_BENCH_VENV:-$root/target/bench-venv}

if [[ $build == 1 || ! -x $bin ]]; then
  echo "building merge_sim (release) ..." >&2
  (cd "$root" && cargo build --release --bin merge_sim) >&2
fi

py="$venv/bin/python"
if [[ ! -x $py ]]; then
  echo "creating venv $venv ..." >&2
  python3 -m venv "$venv" >&2
fi
if ! "$py" - "$HIGHWAY_ENV_PIN" "$GYMNASIUM_PIN" <<'PY' 2>/dev/null; then
import importlib.metadata as m, sys
for pin in sys.argv[1:]:
    name, version = pin.split("==")
    if m.version(name) != version:
        sys.exit(1)
PY
  echo "installing $HIGHWAY_ENV_PIN $GYMNASIUM_PIN into $venv ..." >&2
  "$py" -m pip install --quiet --disable-pip-version-check "$HIGHWAY_ENV_PIN" "$GYMNASIUM_PIN" >&2
fi

args=(--bin "$bin" --root "$root" --reps "$reps" --scenario "$scenario" --hwe-episodes "$hwe_episodes")
if [[ -n $planner ]]; then args+=(--planner "$planner"); fi
if [[ -n $vehicle_model ]]; then args+=(--vehicle-model "$vehicle_model"); fi
if [[ -n $dt_s ]]; then args+=(--dt-s "$dt_s"); fi
if [[ -n $json ]]; then args+=(--json "$json"); fi
exec "$py" "$root/benches/compare_highway_env.py" "${args[@]}"
