#!/usr/bin/env bash
# The BSPs bench/light_agreement.sh compares on, compiled and vised by ericw-tools' own qbsp and
# vis (../shared/anchors/ericw-tools), written to OUT (default /tmp/agree):
#   e1m1.bsp  id's e1m1 (full vis); e1m2.bsp, e2m5.bsp, dm2.bsp the other id maps (vis -fast).
#             Their WAD (id1's gfx/base.wad) is not free, so each map is compiled with a
#             placeholder WAD of flat grey 16x16 textures under its texture names: light needs
#             the names (liquids, sky) and not the pictures.
#   e1m3.bsp, e3m4.bsp  LibreQuake e1m3 and e3m4 with the corpus WADs (vis -fast).
#   start.bsp LibreQuake start, the corpus BSP itself.
# Usage: bench/agreement_bsps.sh [OUT]
set -euo pipefail
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin"
[ -x "$anchor/qbsp" ] || { echo "SKIPPED: $anchor/qbsp not found" >&2; exit 0; }
out="${1:-/tmp/agree}"
mkdir -p "$out"
slipgate=$(slipgate_binary)

# A 16x16 grey picture as an uncompressed 24-bit TGA.
grey_tga() {
  printf '\0\0\2\0\0\0\0\0\0\0\0\0\20\0\20\0\30\0'
  head -c 768 /dev/zero | tr '\0' '\200'
}

pictures=$(mktemp -d)
trap 'rm -rf "$pictures"' EXIT
# id map NAME compiled with a placeholder WAD of its texture names, then vised with the vis
# options that follow NAME.
id_map() {
  local name=$1; shift
  rm -f "$pictures"/*
  # Texture names: the word after a map face's three points.
  sed -n 's/^ *(.*) *(.*) *(.*) *\([^ ]*\) .*/\1/p' "$corpus/public/maps/id/$name.map" \
    | sort -u | while read -r texture; do
      grey_tga > "$pictures/${texture/\*/#}.tga"
    done
  "$slipgate" wad build "$pictures" "$out/$name-placeholder.wad" >/dev/null 2>&1
  sed "s#\"wad\"[[:space:]]*\"[^\"]*\"#\"wad\" \"$out/$name-placeholder.wad\"#" \
    "$corpus/public/maps/id/$name.map" > "$out/$name.map"
  (cd "$out" && "$anchor/qbsp" "$name.map" >/dev/null && "$anchor/vis" "$@" "$name.bsp" >/dev/null)
}
id_map e1m1
for name in e1m2 e2m5 dm2; do id_map "$name" -fast; done

for name in e1m3 e3m4; do
  sed 's#\.\./\.\./\.\./\.\./texture-wads/##g' "$corpus/public/maps/librequake/$name.map" \
    > "$out/$name.map"
  (cd "$out" && "$anchor/qbsp" -wadpath "$corpus/wads/librequake" "$name.map" >/dev/null \
    && "$anchor/vis" -fast "$name.bsp" >/dev/null)
done

cp "$corpus/public/bsp/librequake/start.bsp" "$out/start.bsp"
echo "$out/e1m1.bsp $out/e1m2.bsp $out/e2m5.bsp $out/dm2.bsp $out/e1m3.bsp $out/e3m4.bsp $out/start.bsp"
