#!/usr/bin/env bash
# Instruction counts of each stage (bsp, vis, light, view) on the corpus maps id e1m1 and
# LibreQuake e3m4 under callgrind, one thread: the before/after figures of changes that must not
# cost speed (the move to glam quotes them). Slow: about half an hour per binary.
# Usage: bench/callgrind_stages.sh [SLIPGATE_BINARY] [OUT_DIR]
set -euo pipefail
source "$(dirname "$0")/common.sh"
[ -d "$corpus" ] || { echo "SKIPPED: $corpus not found" >&2; exit 0; }
bin=${1:-$(slipgate_binary)}
out=${2:-$root/target/callgrind}
mkdir -p "$out"
export RAYON_NUM_THREADS=1
count() { # name, command...
  local name=$1; shift
  valgrind --tool=callgrind --callgrind-out-file="$out/$name.out" "$@" >"$out/$name.log" 2>&1
  echo "$name $(grep -o 'Collected : [0-9]*' "$out/$name.log" | awk '{print $3}')"
}
for map in id/e1m1 librequake/e3m4; do
  n=$(basename "$map")
  count "$n-bsp" "$bin" bsp --wad-dir "$corpus/wads/librequake" "$corpus/public/maps/$map.map" "$out/$n.bsp"
  count "$n-vis" "$bin" vis --threads 1 "$out/$n.bsp"
  count "$n-light" "$bin" light --threads 1 "$out/$n.bsp"
  count "$n-view" "$bin" view "$out/$n.bsp" --out "$out/$n.png" --size 320x240
done
