#!/usr/bin/env bash
# Default-quality light, ours against ericw-tools' (../shared/anchors/ericw-tools), on copies of
# the same BSPs, interleaved, ROUNDS rounds (default 3): prints wall, user and system seconds per
# run, then a Markdown table per map: each tool's median wall and CPU seconds and the median of
# the paired rounds' wall ratios (ericw-tools over ours), with their range.
# bench/results/light-side-by-side.md comes from this.
# Usage: [ROUNDS=3] [OURS="--bounce"] [ERICW="-bounce"] bench/light_side_by_side.sh MAP.bsp...
# (vised BSPs; nothing is written beside them). OURS and ERICW are each tool's options for the
# same settings, e.g. OURS="--extra4 --soft --bounce --dirt" ERICW="-extra4 -soft -bounce -dirt".
set -euo pipefail
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin/light"
[ -x "$anchor" ] || { echo "SKIPPED: $anchor not found" >&2; exit 0; }
ours=$(slipgate_binary)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
runs="$work/runs.txt"
# Milliseconds matter: a default-quality e1m1 run takes a tenth of a second.
timed() { local TIMEFORMAT='%3R %3U %3S'; { time "$@" >/dev/null 2>&1; } 2>&1; }
for round in $(seq "${ROUNDS:-3}"); do
  for bsp in "$@"; do
    name=$(basename "$bsp" .bsp)
    cp "$bsp" "$work/ours.bsp"; cp "$bsp" "$work/ericw.bsp"
    # shellcheck disable=SC2086 # the option strings are split on purpose
    echo "$round $name ours  $(timed "$ours" light ${OURS:-} "$work/ours.bsp")" | tee -a "$runs"
    # shellcheck disable=SC2086
    echo "$round $name ericw $(timed "$anchor" ${ERICW:-} "$work/ericw.bsp")" | tee -a "$runs"
  done
done
python3 - "$runs" "${OURS:-default}" <<'PY'
import statistics, sys
from collections import defaultdict
runs = defaultdict(dict)
for line in open(sys.argv[1]):
    rnd, name, tool, wall, user, system = line.split()
    runs[name][(int(rnd), tool)] = (float(wall), float(user) + float(system))
print(f"\n| map ({sys.argv[2]}) | ours wall / CPU | ericw-tools wall / CPU | paired wall ratio (range) |")
print("|---|---|---|---|")
for name, r in runs.items():
    rounds = sorted({k[0] for k in r})
    med = lambda tool, i: statistics.median(r[(n, tool)][i] for n in rounds)
    ratios = [r[(n, "ericw")][0] / max(r[(n, "ours")][0], 1e-3) for n in rounds]
    print(f"| {name} | {med('ours', 0):.3f} / {med('ours', 1):.3f} | "
          f"{med('ericw', 0):.3f} / {med('ericw', 1):.3f} | "
          f"{statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f}) |")
PY
