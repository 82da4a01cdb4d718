#!/usr/bin/env bash
# PF-ISO when every V2V message is lost: collision and near-miss counts over seeded sweeps of
# dense_merge, mixed_traffic and platoon_merge_50, in four conditions on the same instances
# (docs/robustness.md):
#   v2v       the built-in scenario, V2V working;
#   lost      every message lost, PF-ISO's V2V-loss fallback (risk-aware-following, default);
#   lost-off  every message lost, fallback off (interact-with-predictions: the paper's reading);
#   lost-sp   every message lost, PF-SP (the paper's non-cooperative baseline).
# Usage: scripts/v2v_loss_study.sh [RUNS] [PLATOON_RUNS] [SEED]   (defaults 50, 8, 1)
set -euo pipefail
runs=${1:-50}
platoon_runs=${2:-8}
seed=${3:-1}
root=$(cd "$(dirname "$0")/.." && pwd)
bin="$root/target/release/merge_sim"
[[ -x "$bin" ]] || { echo "build first: cargo build --release" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf '%-18s %-9s %5s %11s %11s %12s %12s\n' scenario condition runs collided near_miss min_gap_p5 degraded
for name in dense_merge mixed_traffic platoon_merge_50; do
  n=$runs
  [[ $name == platoon_merge_50 ]] && n=$platoon_runs
  lost="$root/scenarios/experiments/${name}_no_v2v.toml"
  off="$work/${name}_no_v2v_off.toml"
  { cat "$lost"; printf '\n[sim.planner]\nv2v_loss_fallback = "interact-with-predictions"\n'; } > "$off"
  for condition in v2v lost lost-off lost-sp; do
    case $condition in
      v2v) scenario=$name planner=pf-iso ;;
      lost) scenario=$lost planner=pf-iso ;;
      lost-off) scenario=$off planner=pf-iso ;;
      lost-sp) scenario=$lost planner=pf-sp ;;
    esac
    out="$work/$name-$condition.json"
    # Exit code 1 (some runs failed) still writes the aggregate; report it in the table.
    "$bin" sweep --quiet --scenario "$scenario" --planner "$planner" --runs "$n" --seed "$seed" \
      --json "$out" 2>/dev/null || true
    python3 - "$out" "$name" "$condition" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
degraded = sum(r.get("degraded_plans", 0) for r in d["samples"])
gap = d["min_gap_m_p5"]
print(f'{sys.argv[2]:<18} {sys.argv[3]:<9} {d["runs"]:>5} {d["collisions"]:>11} '
      f'{d["near_misses"]:>11} {("-" if gap is None else f"{gap:.2f}"):>12} {degraded:>12}')
PY
  done
done
