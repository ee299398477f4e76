#!/usr/bin/env bash
# Runs the built-in maps under the paper's two regimes (α = 0, β = 0) and the
# defaults, in normalized and literal scoring, and prints a Markdown table.
# The parent plans alone (--children 0), as Eq. (1) is about the parent.
# Usage: scripts/compare-weights.sh [SEED]
set -euo pipefail
cd "$(dirname "$0")/.."
seed=${1:-0}
cargo build --release --quiet
bin=target/release/cpsplan
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| scoring | α | β | map | scans | parent travel (m) | coverage | wall coverage | stop |"
echo "|---|---|---|---|---|---|---|---|---|"
for scoring in normalized literal; do
  for ab in "0.01 0.001" "0 0.001" "0.01 0"; do
    set -- $ab
    for map in office site tunnel; do
      out="$tmp/$scoring-$1-$2-$map"
      "$bin" explore --builtin "$map" --seed "$seed" --planner paper --scoring "$scoring" \
        --alpha "$1" --beta "$2" --children 0 --out "$out" --quiet
      python3 - "$out/summary.json" "$scoring" "$1" "$2" "$map" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {sys.argv[5]} | {s['scans']} | "
      f"{s['parent_travel_m']:.0f} | {s['coverage']:.4f} | {s['wall_coverage']:.4f} | {s['stop_reason']} |")
PY
    done
  done
done
