#!/usr/bin/env bash
# The compiler's time per brush on generated clutter maps (maps/gen/src/clutter.rs: rooms of
# 200 heaped, turned, overlapping blocks and wedges, most of them func_detail) of 1k, 2k, 4k and
# 8k brushes: the whole compile, its CSG phase and its clip hulls, one thread (cost, not
# parallelism), median of RUNS runs (default 3). A cost linear in the brushes that touch gives
# flat columns. Prints a Markdown table; bench/results/bsp-compiler-scaling.md comes from it.
# Usage: [RUNS=3] [SIZES="1000 2000 4000 8000"] bench/csg_scaling.sh
set -euo pipefail
source "$(dirname "$0")/common.sh"
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate -p slipgate-mapgen >/dev/null
bin="${CARGO_TARGET_DIR:-$root/target}/release"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
sizes=${SIZES:-1000 2000 4000 8000}
runs=${RUNS:-3}
for n in $sizes; do
  "$bin/mapgen" clutter --brushes "$n" "$work/clutter$n.map" 2>/dev/null
done
# Interleaved: each run compiles every size once.
for run in $(seq "$runs"); do
  for n in $sizes; do
    RAYON_NUM_THREADS=1 "$bin/slipgate" bsp --wad-dir "$root/maps" --stats "$work/$n.$run.json" \
      "$work/clutter$n.map" "$work/clutter$n.bsp" >/dev/null 2>&1
  done
done
python3 - "$work" "$runs" $sizes <<'EOF'
import json, statistics, sys
work, runs, sizes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
print("| brushes | compile (s) | per brush (ms) | CSG per brush (ms) | hulls per brush (ms) |")
print("|---|---|---|---|---|")
for n in sizes:
    stats = [json.load(open(f"{work}/{n}.{r}.json")) for r in range(1, runs + 1)]
    def median(phase):
        return statistics.median(dict(s["timings"])[phase] for s in stats)
    brushes = stats[0]["brushes"]
    total = median("total")
    csg = median("  csg (sum over models)")
    hulls = median("  hulls (sum over models)")
    ms = lambda s: f"{1000 * s / brushes:.2f}"
    print(f"| {brushes} | {total:.2f} | {ms(total)} | {ms(csg)} | {ms(hulls)} |")
EOF
