#!/usr/bin/env bash
# Explores every map in ../shared/maps from its default start and prints a
# Markdown table of the results. Reports go to ${OUT:-/tmp/cpsplan-shared}/NAME/.
# Runs with the default team (a parent and two children) unless the extra flags
# say otherwise (e.g. --children 0 for the parent alone).
# Usage: scripts/shared-maps.sh [extra explore flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
maps=../shared/maps
out=${OUT:-/tmp/cpsplan-shared}
cargo build --release --quiet
echo "| map | scans | coverage | wall coverage | connected coverage | parent travel (m) | CPS cycles | moves with subgoals | stop | wall time (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for yaml in "$maps"/*.yaml; do
  name=$(basename "$yaml" .yaml)
  target/release/cpsplan explore --map "$yaml" --out "$out/$name" --quiet --max-scans 5000 "$@"
  python3 - "$out/$name/summary.json" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"| {sys.argv[2]} | {s['scans']} | {s['coverage']:.4f} | {s['wall_coverage']:.4f} | {s['connected_coverage']:.4f} | "
      f"{s['parent_travel_m']:.0f} | {s['cps_cycles']} | {s['subgoal_retrievals']} | {s['stop_reason']} | {s['wall_ms'] / 1000:.1f} |")
PY
done
