#!/usr/bin/env bash
# Records episode.json for the three built-in maps (seed 0, default team) and two
# shared maps, or compares them with an earlier recording: a refactor that
# changes no behaviour leaves them byte-identical.
#
# Usage: scripts/same-episodes.sh record DIR    # before the change
#        scripts/same-episodes.sh compare DIR   # after it; exit 1 on any difference
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?usage: same-episodes.sh record|compare DIR}
dir=${2:?usage: same-episodes.sh record|compare DIR}
maps=../shared/maps
cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { # name, explore flags...
  local name=$1
  shift
  target/release/cpsplan explore "$@" --seed 0 --quiet --max-scans 5000 --out "$work/$name"
}
for m in office site tunnel; do run "$m" --builtin "$m"; done
for m in intel_lab aws_small_house; do run "$m" --map "$maps/$m.yaml"; done
status=0
for d in "$work"/*/; do
  name=$(basename "$d")
  case $mode in
    record)
      mkdir -p "$dir/$name"
      cp "$d/episode.json" "$dir/$name/episode.json"
      echo "recorded $name"
      ;;
    compare)
      if cmp -s "$d/episode.json" "$dir/$name/episode.json"; then
        echo "same      $name"
      else
        echo "DIFFERENT $name"
        status=1
      fi
      ;;
    *)
      echo "unknown mode $mode" >&2
      exit 2
      ;;
  esac
done
exit $status
