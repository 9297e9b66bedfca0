#!/usr/bin/env bash
# The visual check of light's bounce (issue #11): LibreQuake's start and e1m3 compiled, vised and
# lit by us with LibreQuake's release settings (-extra4 -soft -bounce -dirt), rendered by our
# viewer from their spawn spots beside LibreQuake's own BSPs of the same maps (in the corpus).
# Prints each picture's mean brightness and their difference; the pictures and difference images
# go to OUT_DIR (default: a temporary folder, kept). LibreQuake's options are not recorded, so the
# same BSP is also lit by ericw-tools' light with the same options when the anchor is present
# (set NO_ANCHOR=1 to skip it: it takes minutes), and compared the same way.
# Usage: [NO_ANCHOR=1] bench/visual_check.sh [OUT_DIR]
set -euo pipefail
source "$(dirname "$0")/common.sh"
[ -d "$corpus" ] || { echo "SKIPPED: $corpus not found"; exit 0; }
out=${1:-$(mktemp -d)}
mkdir -p "$out"
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate -p slipgate-viewer \
  --example compare_lighting >/dev/null
bin="${CARGO_TARGET_DIR:-$root/target}/release"
anchor="$anchor_bin"
palette="$corpus/palette/palette.lmp"
for m in start e1m3; do
  cp "$corpus/public/maps/librequake/$m.map" "$out/$m.map"
  "$bin/slipgate" bsp --wad-dir "$corpus/wads/librequake" "$out/$m.map" "$out/$m.bsp" >/dev/null
  "$bin/slipgate" vis "$out/$m.bsp" >/dev/null
  "$bin/slipgate" light --extra4 --soft --bounce --dirt "$out/$m.bsp" >/dev/null
  echo "## $m: ours (-extra4 -soft -bounce -dirt) against LibreQuake's $m.bsp"
  "$bin/examples/compare_lighting" "$out/$m.bsp" "$corpus/public/bsp/librequake/$m.bsp" \
    "$out/$m" --palette "$palette"
  if [ -z "${NO_ANCHOR:-}" ] && [ -x "$anchor/light" ]; then
    cp "$out/$m.bsp" "$out/ericw_$m.bsp"
    rm -f "$out/ericw_$m.lit"
    "$anchor/light" -extra4 -soft -bounce -dirt "$out/ericw_$m.bsp" >/dev/null
    echo "## $m: ours against ericw-tools' light of the same BSP with the same options"
    "$bin/examples/compare_lighting" "$out/$m.bsp" "$out/ericw_$m.bsp" "$out/ericw_$m" \
      --palette "$palette"
  fi
done
echo "pictures in $out"
