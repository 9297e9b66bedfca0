#!/usr/bin/env bash
# Times bsp, vis and light on corpus maps with the release build: the figures in README.md.
# Usage: bench/corpus.sh [MAP.map ...]   (default: id e1m1 and LibreQuake e3m4 from ../shared)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
corpus="$root/../shared/corpus"
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate >/dev/null
slipgate="${CARGO_TARGET_DIR:-$root/target}/release/slipgate"
maps=("$@")
[ ${#maps[@]} -gt 0 ] || maps=("$corpus/public/maps/id/e1m1.map" "$corpus/public/maps/librequake/e3m4.map")
work=$(mktemp -d)
for src in "${maps[@]}"; do
  name=$(basename "$src" .map)
  cp "$src" "$work/"
  cd "$work"
  /usr/bin/time -f "$name bsp: %e s, %M KB" "$slipgate" bsp --wad-dir "$corpus/wads/librequake" "$name.map" >/dev/null 2>bsp.err || { cat bsp.err; exit 1; }
  tail -1 bsp.err
  /usr/bin/time -f "$name vis (full): %e s" "$slipgate" vis "$name.bsp" 2>&1 >/dev/null | tail -1
  cp "$name.bsp" unlit.bsp
  for mode in "" "--extra4 --soft"; do
    cp unlit.bsp "$name.bsp"
    # shellcheck disable=SC2086
    /usr/bin/time -f "$name light ${mode:-default}: %e s" "$slipgate" light $mode "$name.bsp" 2>&1 >/dev/null | tail -1
  done
done
rm -rf "$work"
