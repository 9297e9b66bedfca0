#!/usr/bin/env bash
# Both light tools against the independent reference (reference.py) on the benchmark forms of
# corpus maps: each map's benchmark form (benchmark_map.py) compiled and fully vised by
# ericw-tools' qbsp and vis, then lit by Slipgate and by ericw-tools' light at each setting,
# RUNS times each, interleaved (the median wall time counts); the last lit BSP of each is judged
# by reference.py. Prints a Markdown table; bench/results/light-independent.md comes from it.
# id's maps get a placeholder WAD of grey textures under their names (light needs the names:
# liquids and sky); LibreQuake's maps use the corpus WADs.
# Usage: [RUNS=3] [KEEP=DIR] bench/independent/validate.sh [MAP.map...]
#        (default maps: id e1m1, LibreQuake start and e1m3)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
shared="$root/../shared"
anchor="$shared/anchors/ericw-tools/bin"
[ -x "$anchor/qbsp" ] || { echo "SKIPPED: $anchor/qbsp not found" >&2; exit 0; }
python3 -c 'import mitsuba, numpy' 2>/dev/null \
  || { echo "SKIPPED: Python's mitsuba and numpy are missing (pip install mitsuba numpy)" >&2; exit 0; }
runs=${RUNS:-3}
if [ $# -eq 0 ]; then
  set -- "$shared/corpus/public/maps/id/e1m1.map" "$shared/corpus/public/maps/librequake/start.map" \
    "$shared/corpus/public/maps/librequake/e1m3.map"
fi
cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate >/dev/null
slipgate="${CARGO_TARGET_DIR:-$root/target}/release/slipgate"
work=${KEEP:-$(mktemp -d)}
mkdir -p "$work"
[ -n "${KEEP:-}" ] || trap 'rm -rf "$work"' EXIT

grey_tga() {
  printf '\0\0\2\0\0\0\0\0\0\0\0\0\20\0\20\0\30\0'
  head -c 768 /dev/zero | tr '\0' '\200'
}

# The benchmark form of map $1 compiled and vised into $work/NAME/NAME.bsp.
compile() {
  local map=$1 name dir
  name=$(basename "$map" .map)
  dir="$work/$name"
  mkdir -p "$dir"
  python3 "$here/benchmark_map.py" "$map" "$dir/$name.map"
  if grep -q 'texture-wads/' "$map"; then
    sed -i 's#\.\./\.\./\.\./\.\./texture-wads/##g' "$dir/$name.map"
    (cd "$dir" && "$anchor/qbsp" -wadpath "$shared/corpus/wads/librequake" "$name.map" >qbsp.log)
  else
    local pictures="$dir/pictures"
    mkdir -p "$pictures"
    sed -n 's/^ *(.*) *(.*) *(.*) *\([^ ]*\) .*/\1/p' "$map" | sort -u | while read -r texture; do
      grey_tga >"$pictures/${texture/\*/#}.tga"
    done
    "$slipgate" wad build "$pictures" "$dir/placeholder.wad" >/dev/null 2>&1
    sed -i "s#\"wad\"[[:space:]]*\"[^\"]*\"#\"wad\" \"$dir/placeholder.wad\"#" "$dir/$name.map"
    (cd "$dir" && "$anchor/qbsp" "$name.map" >qbsp.log)
  fi
  (cd "$dir" && "$anchor/vis" "$name.bsp" >vis.log)
}

# Wall seconds of light run $2... on a fresh copy of $1's BSP in directory $3.
light_once() {
  local bsp=$1 out=$2
  shift 2
  rm -rf "$out"
  mkdir -p "$out"
  cp "$bsp" "$out/"
  local start end
  start=$(date +%s.%N)
  "$@" "$out/$(basename "$bsp")" >"$out/light.log" 2>&1
  end=$(date +%s.%N)
  echo "$end - $start" | bc
}

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

echo "| map | setting | Slipgate: time | Slipgate: error | ericw-tools: time | ericw-tools: error | noise | drawn luxels judged | reference time |"
echo "|---|---|---|---|---|---|---|---|---|"
for map in "$@"; do
  name=$(basename "$map" .map)
  compile "$map"
  bsp="$work/$name/$name.bsp"
  for setting in default extra4-soft; do
    if [ "$setting" = default ]; then opts=(); else opts=(-extra4 -soft); fi
    sg_times=()
    ew_times=()
    for _ in $(seq "$runs"); do
      sg_times+=("$(light_once "$bsp" "$work/$name/slipgate-$setting" "$slipgate" light "${opts[@]}")")
      ew_times+=("$(light_once "$bsp" "$work/$name/ericw-$setting" "$anchor/light" "${opts[@]}")")
    done
    sg_time=$(printf '%s\n' "${sg_times[@]}" | median)
    ew_time=$(printf '%s\n' "${ew_times[@]}" | median)
    sg_out=$(python3 "$here/reference.py" --quiet "$work/$name/slipgate-$setting/$name.bsp")
    ew_out=$(python3 "$here/reference.py" --quiet "$work/$name/ericw-$setting/$name.bsp")
    # last line: rmse R over N drawn luxels; noise S
    read -r _ sg_rmse _ luxels _ _ _ noise <<<"$(tail -n 1 <<<"$sg_out")"
    read -r _ ew_rmse _ _ _ _ _ _ <<<"$(tail -n 1 <<<"$ew_out")"
    ref_time=$(head -n 1 <<<"$sg_out" | sed 's/.*reference time \([0-9.]*\) s.*/\1/')
    subset=$(head -n 1 <<<"$sg_out" | sed 's/subset: 1 in \([0-9]*\).*/\1/')
    printf '| %s | %s | %.2f s | %.2f | %.2f s | %.2f | %.2f | %s (1 face in %s) | %.0f s |\n' \
      "$name" "$setting" "$sg_time" "$sg_rmse" "$ew_time" "$ew_rmse" "${noise%;}" "$luxels" "$subset" "$ref_time"
  done
done
