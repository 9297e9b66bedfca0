#!/usr/bin/env bash
# The price of a light change, side by side with ericw-tools (../shared/anchors/ericw-tools):
# two builds of `slipgate` (before and after the change) and ericw-tools' `light` light copies of
# the same vised BSP, interleaved, ROUNDS rounds (default 3). Prints a Markdown row per map: each
# one's median wall seconds and ericw-tools' median over each build's.
# Usage: [ROUNDS=3] [OURS="--bounce"] [ERICW="-bounce"] bench/light_before_after.sh BEFORE AFTER MAP.bsp...
set -euo pipefail
[ $# -ge 3 ] || { sed -n '2,7s/^# \{0,1\}//p' "$0"; exit 2; }
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin/light"
[ -x "$anchor" ] || { echo "SKIPPED: $anchor not found" >&2; exit 0; }
before=$1; after=$2; shift 2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
timed() { local TIMEFORMAT='%3R'; { time "$@" >/dev/null 2>&1; } 2>&1; }
echo "| map (${OURS:-default}) | before | after | ericw-tools | ericw-tools / before | ericw-tools / after |"
echo "|---|---|---|---|---|---|"
for bsp in "$@"; do
  for round in $(seq "${ROUNDS:-3}"); do
    for tool in before after ericw; do
      cp "$bsp" "$work/t.bsp"; rm -f "$work/t.lit"
      # shellcheck disable=SC2086 # the option strings are split on purpose
      case $tool in
        before) echo "$tool $(timed "$before" light ${OURS:-} "$work/t.bsp")" ;;
        after) echo "$tool $(timed "$after" light ${OURS:-} "$work/t.bsp")" ;;
        ericw) echo "$tool $(timed "$anchor" ${ERICW:-} "$work/t.bsp")" ;;
      esac
    done
  done >"$work/runs.txt"
  python3 - "$work/runs.txt" "$(basename "$bsp" .bsp)" <<'PY'
import statistics, sys
from collections import defaultdict
t = defaultdict(list)
for line in open(sys.argv[1]):
    tool, wall = line.split()
    t[tool].append(float(wall))
m = {k: statistics.median(v) for k, v in t.items()}
print(f"| {sys.argv[2]} | {m['before']:.3f} s | {m['after']:.3f} s | {m['ericw']:.3f} s | "
      f"{m['ericw'] / m['before']:.2f}x | {m['ericw'] / m['after']:.2f}x |")
PY
done
