#!/usr/bin/env bash
# Per-face agreement of our light with ericw-tools' (../shared/anchors/ericw-tools) on copies of
# the same vised BSPs at the same setting: for each map, the share of faces whose mean light is
# within 5 levels of ericw-tools', the faces only one tool gives a lightmap, and the faces that
# differ most (light/examples/ericw_agreement.rs). The `MAP.texinfo.json` ericw-tools' qbsp writes
# beside a BSP goes with both copies. bench/results/light-agreement.md comes from it.
# Usage: [OURS="--extra4 --soft"] [ERICW="-extra4 -soft"] [WORST=20] bench/light_agreement.sh MAP.bsp...
set -euo pipefail
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin/light"
[ -x "$anchor" ] || { echo "SKIPPED: $anchor not found" >&2; exit 0; }
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate -p slipgate-light --bins \
  --example ericw_agreement >/dev/null
target="${CARGO_TARGET_DIR:-$root/target}/release"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
for bsp in "$@"; do
  name=$(basename "$bsp" .bsp)
  cp "$bsp" "$work/ours.bsp"; cp "$bsp" "$work/ericw.bsp"
  rm -f "$work"/*.texinfo.json
  # The per-face keys ericw-tools' qbsp writes beside its BSP (`_phong`, `_minlight`, ...): both
  # tools read them as a mapper's light run would.
  if [ -f "${bsp%.bsp}.texinfo.json" ]; then
    cp "${bsp%.bsp}.texinfo.json" "$work/ours.texinfo.json"
    cp "${bsp%.bsp}.texinfo.json" "$work/ericw.texinfo.json"
  fi
  # shellcheck disable=SC2086 # the option strings are split on purpose
  "$target/slipgate" light ${OURS:-} "$work/ours.bsp" >/dev/null 2>&1
  # shellcheck disable=SC2086
  "$anchor" ${ERICW:-} "$work/ericw.bsp" >/dev/null 2>&1
  echo "## $name (ours: ${OURS:-default}, ericw-tools: ${ERICW:-default})"
  "$target/examples/ericw_agreement" "$work/ours.bsp" "$work/ericw.bsp" "${WORST:-20}"
done
