#!/usr/bin/env bash
# The README's speed table: `slipgate report` with the release build on the project's maps and the
# corpus maps (id e1m1, LibreQuake e3m4), side by side with ericw-tools
# (../shared/anchors/ericw-tools) when it is present, best of RUNS interleaved runs. Writes
# report.md, report.json, report.html and the plots into OUT (default target/report).
# Usage: [RUNS=3] [OUT=DIR] bench/corpus.sh [MAP.map ...]
set -euo pipefail
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin"
slipgate=$(slipgate_binary)
args=(--runs "${RUNS:-3}" --out-dir "${OUT:-$root/target/report}")
if [ -x "$anchor/qbsp" ]; then
  args+=(--anchor "$anchor")
else
  echo "note: $anchor not found: Slipgate only" >&2
fi
cd "$root"
exec "$slipgate" report "${args[@]}" "$@"
