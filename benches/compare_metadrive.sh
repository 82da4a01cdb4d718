#!/usr/bin/env bash
# Side-by-side throughput: simulated vehicle-seconds per wall-clock second of mergesim at >= 10
# Rapier vehicles (the platoon of `merge_sim scenario platoon --vehicles N`) and of MetaDrive
# (Bullet ray-cast vehicles, its default traffic, physics only: no rendering, no image
# observation), measured in one run on this machine, paired and interleaved (MetaDrive,
# mergesim run on one core, mergesim run on all cores, mergesim sweep on all cores, MetaDrive,
# ...), one untimed warm-up of each first. Prints a Markdown table on stdout (progress and
# MetaDrive's own output on stderr); --json PATH also writes every sample.
#
# What each side simulates and what is timed: the docstring of benches/compare_metadrive.py.
# In short: MetaDrive's MetaDriveEnv defaults (3-block procedural map, traffic_density 0.1,
# trigger traffic, 0.02 s Bullet steps x decision_repeat 5, lidar-state observation) with the
# ego driven by MetaDrive's IDMPolicy, timed around env.reset()/env.step(); mergesim's whole
# `merge_sim run` / `merge_sim sweep` process, timed around the subprocess.
#
# Setup: a venv in $MERGESIM_METADRIVE_VENV (default target/bench-venv-metadrive, git-ignored
# with target/), created with `python3 -m venv` if missing, into which pip installs the pinned
# versions below if they are not there (the versions this script was written and run against).
# MetaDrive downloads its assets (models, textures) from GitHub on first use; physics-only it
# needs none of them, but it checks for two files before it runs and would try to download
# otherwise. This script therefore creates, inside the venv's metadrive package, if missing:
#   metadrive/assets/version.txt          holding the package's version (metadrive.version.VERSION):
#                                         BaseEngine.try_pull_asset() compares it with VERSION
#   metadrive/assets/textures/grass1/GroundGrassGreen002_COL_1K.jpg
#                                         a 4x4 green JPEG placeholder: AssetLoader.should_update_asset()
#                                         requires the default ground texture to exist (it is only
#                                         loaded when rendering)
# A real asset download (`python -m metadrive.pull_asset`) is left alone: existing files are kept.
# --md-traffic-density D sets MetaDrive's traffic_density; 0.2 is the smallest density (in steps
# of 0.05) with at least 10 driving vehicles on average, the matched comparison planned in
# benches/metadrive_matched_density.md.
# --dt-s DT sets the mergesim platoon's physics step ([sim] dt_s; default 0.002 s): the steps at
# which the vehicle is valid are measured by benches/physics_step_validity.py.
# The merge_sim binary: --bin PATH, else target/release/merge_sim, built
# (`cargo build --release --bin merge_sim`) if missing or with --build.
# Needs bash, python3 (with venv/ensurepip), pip access to PyPI (no other network access).
#
# Usage: benches/compare_metadrive.sh [--reps N] [--vehicles N] [--sweep-runs K] [--threads T]
#                                     [--md-episodes N] [--md-procs P] [--md-traffic-density D]
#                                     [--dt-s DT] [--also-speed-program NAME] [--also-planner NAME]
#                                     [--json PATH] [--bin PATH] [--build] [--help]
set -euo pipefail

METADRIVE_PIN="metadrive-simulator==0.4.3"
PANDA3D_PIN="panda3d==1.10.13"
GYMNASIUM_PIN="gymnasium==1.4.0"
NUMPY_PIN="numpy==2.4.6"

usage() {
  cat <<'EOF'
Usage: benches/compare_metadrive.sh [OPTIONS]

Simulated vehicle-seconds per wall-clock second: mergesim's platoon of N Rapier vehicles
(`merge_sim run`, on one core and on all cores, and `merge_sim sweep` on all cores) vs MetaDrive
(default traffic, physics only, IDM ego), interleaved and paired in one run. Markdown table on
stdout. See benches/compare_metadrive.py's docstring for what is simulated and timed.

Options:
  --reps N          repetitions of each variant, interleaved (default 5)
  --vehicles N      mergesim platoon size (default 10)
  --sweep-runs K    instances per `merge_sim sweep` repetition (default 4)
  --threads T       worker threads of the sweep (default: every core)
  --md-episodes N   MetaDrive episodes per repetition (default 10, seeds 0..N-1)
  --dt-s DT         physics step of the mergesim platoon in seconds, [sim] dt_s, in
                    [0.0001, 0.02] (default: the scenario's, 0.002 s = 500 Hz). Which steps keep
                    the vehicle valid: benches/physics_step_validity.py
  --also-speed-program NAME
                    also run the mergesim sweep with this [sim.planner] speed_program
                    (e.g. newton-qp-banded), interleaved with the other variants
  --also-planner NAME
                    also run the mergesim `run` on one core and the `sweep` with `--planner NAME`
                    (every vehicle) in place of PF-ISO, interleaved with the other variants:
                    e.g. idm-mobil (IDM + MOBIL, the kind of driver MetaDrive's IDMPolicy is), to
                    set the simulator's cost beside the planner's. A name merge_sim refuses
                    (unknown, or one the platoon cannot run): exit 2
  --md-procs P      MetaDrive processes run at once for the all-cores row (default: every
                    core; 1 leaves the row out)
  --md-traffic-density D
                    MetaDrive's traffic_density, a number in (0, 1] (default: MetaDrive's own,
                    0.1: 5.5 driving vehicles on average over the 10 episodes; 0.2: 11.4, the
                    matched comparison of benches/metadrive_matched_density.md)
  --json PATH       also write all samples and the environment as JSON
  --bin PATH        merge_sim binary to use (default target/release/merge_sim, built if missing)
  --build           run `cargo build --release --bin merge_sim` even if the binary exists
  -h, --help        this help

Environment:
  MERGESIM_METADRIVE_VENV  venv directory (default target/bench-venv-metadrive in the checkout)
EOF
}

reps=5
vehicles=10
sweep_runs=4
threads=""
md_episodes=10
md_procs=""
md_density=""
dt_s=""
json=""
also_program=""
also_planner=""
bin=""
build=0
need() { [[ $# -ge 2 && -n $2 ]] || { echo "error: $1 needs a value" >&2; exit 2; }; }
posint() { [[ $2 =~ ^[1-9][0-9]*$ ]] || { echo "error: $1 must be a positive integer" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
  case $1 in
    --reps) need "$@"; posint "$1" "$2"; reps=$2; shift 2 ;;
    --vehicles) need "$@"; posint "$1" "$2"; vehicles=$2; shift 2 ;;
    --sweep-runs) need "$@"; posint "$1" "$2"; sweep_runs=$2; shift 2 ;;
    --threads) need "$@"; posint "$1" "$2"; threads=$2; shift 2 ;;
    --md-episodes) need "$@"; posint "$1" "$2"; md_episodes=$2; shift 2 ;;
    --md-procs) need "$@"; posint "$1" "$2"; md_procs=$2; shift 2 ;;
    --md-traffic-density) need "$@"
      [[ $2 =~ ^(0?\.[0-9]*[1-9][0-9]*|1(\.0*)?)$ ]] || { echo "error: --md-traffic-density must be a number in (0, 1], got '$2'" >&2; exit 2; }
      md_density=$2; shift 2 ;;
    --dt-s) need "$@"
      [[ $2 =~ ^0?\.[0-9]+$ ]] && awk -v d="$2" 'BEGIN { exit !(d >= 0.0001 && d <= 0.02) }' \
        || { echo "error: --dt-s must be a number of seconds in [0.0001, 0.02], got '$2'" >&2; exit 2; }
      dt_s=$2; shift 2 ;;
    --also-speed-program) need "$@"; also_program=$2; shift 2 ;;
    --also-planner) need "$@"; also_planner=$2; shift 2 ;;
    --json) need "$@"; json=$2; shift 2 ;;
    --bin) need "$@"; bin=$2; shift 2 ;;
    --build) build=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "error: unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv=${MERGESIM_METADRIVE_VENV:-$root/target/bench-venv-metadrive}

if [[ -z $bin ]]; then
  bin="$root/target/release/merge_sim"
  if [[ $build == 1 || ! -x $bin ]]; then
    echo "building merge_sim (release) ..." >&2
    (cd "$root" && cargo build --release --bin merge_sim) >&2
  fi
elif [[ $build == 1 ]]; then
  echo "error: --build and --bin exclude each other" >&2; exit 2
fi
[[ -x $bin ]] || { echo "error: $bin is not an executable" >&2; exit 2; }

py="$venv/bin/python"
if [[ ! -x $py ]]; then
  echo "creating venv $venv ..." >&2
  python3 -m venv "$venv" >&2
fi
pins=("$METADRIVE_PIN" "$PANDA3D_PIN" "$GYMNASIUM_PIN" "$NUMPY_PIN")
if ! "$py" - "${pins[@]}" <<'PY' 2>/dev/null; then
import importlib.metadata as m, sys
for pin in sys.argv[1:]:
    name, version = pin.split("==")
    if m.version(name) != version:
        sys.exit(1)
PY
  echo "installing ${pins[*]} into $venv ..." >&2
  "$py" -m pip install --quiet --disable-pip-version-check "${pins[@]}" >&2
fi

# The asset placeholders (see the header): only files that are missing are created.
"$py" - <<'PY' >&2
import importlib.util, pathlib
spec = importlib.util.find_spec("metadrive")
pkg = pathlib.Path(spec.origin).parent
ns = {}
exec((pkg / "version.py").read_text(), ns)  # metadrive.version without importing metadrive
version_txt = pkg / "assets" / "version.txt"
texture = pkg / "assets" / "textures" / "grass1" / "GroundGrassGreen002_COL_1K.jpg"
if not version_txt.exists():
    version_txt.parent.mkdir(parents=True, exist_ok=True)
    version_txt.write_text(ns["VERSION"] + "\n")
    print(f"created {version_txt} ({ns['VERSION']})")
if not texture.exists():
    from PIL import Image
    texture.parent.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (4, 4), (60, 110, 40)).save(texture, "JPEG")
    print(f"created {texture} (4x4 placeholder)")
PY

args=(--bin "$bin" --root "$root" --reps "$reps" --vehicles "$vehicles" --sweep-runs "$sweep_runs"
      --md-episodes "$md_episodes")
if [[ -n $threads ]]; then args+=(--threads "$threads"); fi
if [[ -n $md_procs ]]; then args+=(--md-procs "$md_procs"); fi
if [[ -n $md_density ]]; then args+=(--md-traffic-density "$md_density"); fi
if [[ -n $dt_s ]]; then args+=(--dt-s "$dt_s"); fi
if [[ -n $json ]]; then args+=(--json "$json"); fi
if [[ -n $also_program ]]; then args+=(--also-speed-program "$also_program"); fi
if [[ -n $also_planner ]]; then args+=(--also-planner "$also_planner"); fi
exec "$py" "$root/benches/compare_metadrive.py" "${args[@]}"
