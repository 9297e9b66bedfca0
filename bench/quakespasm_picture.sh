#!/usr/bin/env bash
# A picture of a BSP as QuakeSpasm draws it (its lightmaps, its .lit beside it), seen from a
# point: the BSP is copied with its info_player_start moved there, and QuakeSpasm's client, in a
# virtual X display with Mesa's software OpenGL, screenshots the view with LibreQuake's game
# code (../shared/engine/id1). For pictures of two lightings of one map side by side.
# Usage: bench/quakespasm_picture.sh MAP.bsp "X Y Z" YAW OUT.png
#   X Y Z  where the player stands (the eyes are 22 units higher); YAW the view's heading.
set -euo pipefail
[ $# -eq 4 ] || { sed -n '2,7p' "$0" >&2; exit 2; }
bsp=$1 origin=$2 yaw=$3 out=$4
source "$(dirname "$0")/common.sh"
id1="$root/../shared/engine/id1"
client=$(command -v quakespasm || echo /usr/games/quakespasm)
for need in "$id1" "$client" "$(command -v xvfb-run || true)"; do
  [ -e "$need" ] || { echo "SKIPPED: ${need:-xvfb-run} not found" >&2; exit 0; }
done
work=$(mktemp -d)
game="slipgate-picture-$$"
# QuakeSpasm writes screenshots under the account's home (not $HOME), per game.
written="$(getent passwd "$(id -u)" | cut -d: -f6)/.quakespasm/$game"
trap 'rm -rf "$work" "$written"' EXIT
mkdir -p "$work/$game/maps" "$work/home"
ln -s "$id1" "$work/id1"
lit="${bsp%.bsp}.lit"
[ -f "$lit" ] && cp "$lit" "$work/$game/maps/view.lit"
# The first info_player_start gets the new origin and angle; the new entity text goes at the
# end of the file (the lump's offset and length updated), so no other lump moves.
python3 - "$bsp" "$work/$game/maps/view.bsp" "$origin" "$yaw" <<'PY'
import re, struct, sys
src, dst, origin, yaw = sys.argv[1:]
data = bytearray(open(src, 'rb').read())
offset, length = struct.unpack_from('<ii', data, 4)
text = data[offset:offset + length].decode('latin-1').rstrip('\0')
start = next(b for b in re.finditer(r'\{[^{}]*\}', text) if '"info_player_start"' in b.group(0))
body = re.sub(r'\s*"(origin|angle|mangle)"\s*"[^"]*"', '', start.group(0)[1:-1])
new = '{' + body.rstrip() + f'\n"origin" "{origin}"\n"angle" "{yaw}"\n}}'
text = text[:start.start()] + new + text[start.end():]
data.extend(b'\0' * (-len(data) % 4))
struct.pack_into('<ii', data, 4, len(data), len(text) + 1)
data.extend(text.encode('latin-1') + b'\0')
open(dst, 'wb').write(data)
PY
waits() { for _ in $(seq "$1"); do echo wait; done; }
{
  echo "host_framerate 0.02"; echo "host_maxfps 1000"; echo "con_notifytime 0"
  echo "noexit 1"; echo "map view"; waits 40
  echo "god"; echo "notarget"; echo "crosshair 0"; echo "viewsize 120"; echo "r_drawviewmodel 0"
  echo "scr_showfps 0"; waits 10; echo "con_notifytime 0"; echo "clear"
  waits 2; echo "screenshot"; waits 2; echo "quit"
} > "$work/$game/picture.cfg"
HOME="$work/home" LP_NUM_THREADS=0 MESA_SHADER_CACHE_DISABLE=true \
  timeout 300 xvfb-run -a -s "-screen 0 640x480x24" "$client" -basedir "$work" -game "$game" \
  -width 640 -height 480 -window -noudp -nosound +exec picture.cfg >"$work/log" 2>&1 || true
shot=$(find "$written" -name "spasm*.png" 2>/dev/null | head -1)
[ -n "$shot" ] || { echo "no screenshot; QuakeSpasm said:" >&2; tail -20 "$work/log" >&2; exit 1; }
cp "$shot" "$out"
echo "$out"
