#!/usr/bin/env bash
# Times bsp, vis and light on corpus maps with the release build, side by side with the reference
# compiler (ericw-tools, ../shared/anchors/ericw-tools) when it is present: the figures in
# README.md. Each run does every step of both tools in turn (interleaved, so both see the same
# machine), and the table gives the best of RUNS runs.
#   - bsp: both compile the same .map.
#   - vis: both run full vis on our BSP and portals (the same input).
#   - light: both light our BSP (after our full vis): default, `-extra4 -soft`, `-bounce`, and
#     `-extra4 -soft -bounce -dirt` (LibreQuake's release settings).
# Usage: [RUNS=3] bench/corpus.sh [MAP.map ...]   (default: id e1m1 and LibreQuake e3m4)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
corpus="$root/../shared/corpus"
anchor="$root/../shared/anchors/ericw-tools/bin"
runs=${RUNS:-3}
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate >/dev/null
slipgate="${CARGO_TARGET_DIR:-$root/target}/release/slipgate"
maps=("$@")
[ ${#maps[@]} -gt 0 ] || maps=("$corpus/public/maps/id/e1m1.map" "$corpus/public/maps/librequake/e3m4.map")
ericw=yes
[ -x "$anchor/qbsp" ] || { ericw=; echo "note: $anchor not found: Slipgate only" >&2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# ericw's qbsp appends a map's whole relative "wad" path to -wadpath; LibreQuake's maps name
# ../../../../texture-wads/NAME.wad, so give it a folder four levels below a texture-wads link.
mkdir -p "$work/wp/a/b/c/d"
ln -s "$corpus/wads/librequake" "$work/wp/texture-wads"

# timed NAME COMMAND...: runs the command in $work, appends "NAME seconds KB" to $work/times.
timed() {
  local name=$1
  shift
  if ! /usr/bin/time -f "$name %e %M" -a -o "$work/times" "$@" >"$work/last.log" 2>&1; then
    tail -5 "$work/last.log" >&2
    echo "failed: $*" >&2
    exit 1
  fi
}

cd "$work"
for run in $(seq "$runs"); do
  for src in "${maps[@]}"; do
    m=$(basename "$src" .map)
    cp "$src" "$m.map"
    timed "$m/bsp/slipgate" "$slipgate" bsp --wad-dir "$corpus/wads/librequake" "$m.map" "$m.bsp"
    [ -z "$ericw" ] || timed "$m/bsp/ericw" "$anchor/qbsp" -wadpath "$work/wp/a/b/c/d" "$m.map" "e_$m.bsp"
    cp "$m.bsp" "v_$m.bsp"
    cp "$m.prt" "v_$m.prt"
    timed "$m/vis/slipgate" "$slipgate" vis "$m.bsp"
    [ -z "$ericw" ] || timed "$m/vis/ericw" "$anchor/vis" "v_$m.bsp"
    for mode in default "-extra4 -soft" "-bounce" "-extra4 -soft -bounce -dirt"; do
      flags=${mode#default}
      key=${mode// /}
      cp "$m.bsp" "l_$m.bsp"
      # shellcheck disable=SC2086
      timed "$m/light$key/slipgate" "$slipgate" light $flags "l_$m.bsp"
      cp "$m.bsp" "l_$m.bsp"
      # shellcheck disable=SC2086
      [ -z "$ericw" ] || timed "$m/light$key/ericw" "$anchor/light" $flags "l_$m.bsp"
    done
  done
  echo "run $run of $runs done" >&2
done

# Best time (and its peak memory) per step and tool, then the table.
echo "| stage | map | Slipgate | ericw-tools | ratio |"
echo "|---|---|---|---|---|"
awk '
  { split($1, k, "/"); step = k[1] "/" k[2]; tool = k[3]
    if (!(step SUBSEP tool in best) || $2 < best[step, tool]) { best[step, tool] = $2; mem[step, tool] = $3 }
    if (!(step in seen)) { seen[step] = 1; order[++n] = step } }
  END {
    for (i = 1; i <= n; i++) {
      split(order[i], k, "/"); s = order[i]
      ours = sprintf("%.2f s, %d MB", best[s, "slipgate"], mem[s, "slipgate"] / 1024)
      theirs = "-"; ratio = "-"
      if ((s SUBSEP "ericw") in best) {
        theirs = sprintf("%.2f s, %d MB", best[s, "ericw"], mem[s, "ericw"] / 1024)
        if (best[s, "slipgate"] > 0) ratio = sprintf("%.1fx", best[s, "ericw"] / best[s, "slipgate"])
      }
      printf "| %s | %s | %s | %s | %s |\n", k[2], k[1], ours, theirs, ratio
    }
  }' "$work/times"
