#!/usr/bin/env bash
# Instruction counts of the compiler alone under callgrind, one thread (`slipgate bsp --threads
# 1`), on the maps given (paths, or names of corpus maps such as id/e1m1): the before/after
# figures of compiler changes in bench/results/bsp-compiler-speed.md. A minute or two a map.
# Usage: [SLIPGATE=path/to/slipgate] bench/callgrind_bsp.sh MAP... (default id/e1m1
# librequake/start ericw-tools/q1_mountain)
set -euo pipefail
source "$(dirname "$0")/common.sh"
[ -d "$corpus" ] || { echo "SKIPPED: $corpus not found" >&2; exit 0; }
bin=$(slipgate_binary)
maps=("$@")
[ ${#maps[@]} -gt 0 ] || maps=(id/e1m1 librequake/start ericw-tools/q1_mountain)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
for map in "${maps[@]}"; do
  [ -f "$map" ] || map="$corpus/public/maps/$map.map"
  valgrind --tool=callgrind --callgrind-out-file="$work/out" "$bin" bsp --threads 1 \
    --wad-dir "$corpus/wads/librequake" --wad-dir "$corpus/wads/ericw-tools" "$map" \
    "$work/map.bsp" >"$work/log" 2>&1
  echo "$(basename "$map" .map) $(grep -o 'Collected : [0-9]*' "$work/log" | awk '{print $3}')"
done
