#!/usr/bin/env bash
# `slipgate bsp` against ericw-tools' qbsp (../shared/anchors/ericw-tools) on every corpus map, or
# on the maps given: wall seconds and peak memory (max RSS) of each, RUNS interleaved rounds
# (default 5), their medians and ratios. Prints a Markdown table;
# bench/results/bsp-compiler-speed.md comes from it.
# Usage: [RUNS=5] [SLIPGATE=path/to/slipgate] bench/bsp_ratio.sh [MAP.map ...] (SLIPGATE: another
# build of the command, instead of building this tree's)
set -euo pipefail
source "$(dirname "$0")/common.sh"
anchor="$anchor_bin"
[ -x "$anchor/qbsp" ] || { echo "SKIPPED: $anchor/qbsp not found" >&2; exit 0; }
ours=$(slipgate_binary)
maps=("$@")
if [ ${#maps[@]} -eq 0 ]; then
  mapfile -t maps < <(ls "$corpus"/public/maps/*/*.map)
fi
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
export LD_LIBRARY_PATH="$anchor${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
python3 - "$ours" "$anchor/qbsp" "$corpus" "$work" "${RUNS:-5}" "${maps[@]}" <<'EOF'
import os, statistics, subprocess, sys, time
ours, qbsp, corpus, work, runs, maps = *sys.argv[1:5], int(sys.argv[5]), sys.argv[6:]
wads = [f"{corpus}/wads/librequake", f"{corpus}/wads/ericw-tools"]
tools = {
    "ericw": lambda m: [qbsp, "-wadpath", wads[0], "-wadpath", wads[1], m, f"{work}/ericw.bsp"],
    "ours": lambda m: [ours, "bsp", "--wad-dir", wads[0], "--wad-dir", wads[1], m, f"{work}/ours.bsp"],
}

def measure(command):
    """Wall seconds and peak resident KiB of one run (of that child alone)."""
    start = time.perf_counter()
    child = subprocess.Popen(command, cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, _, usage = os.wait4(child.pid, 0)
    return time.perf_counter() - start, usage.ru_maxrss

seconds, kib = {}, {}
for _ in range(runs):
    for m in maps:
        for tool, command in tools.items():
            s, k = measure(command(m))
            seconds.setdefault((m, tool), []).append(s)
            kib.setdefault((m, tool), []).append(k)
print("| map | .map size | ericw-tools qbsp (s) | slipgate bsp (s) | speed ratio | ericw-tools peak (MiB) | slipgate peak (MiB) | memory share |")
print("|---|---|---|---|---|---|---|---|")
for m in maps:
    med = lambda d, tool: statistics.median(d[(m, tool)])
    t_e, t_o = med(seconds, "ericw"), med(seconds, "ours")
    m_e, m_o = med(kib, "ericw") / 1024, med(kib, "ours") / 1024
    name = os.path.basename(m)[:-4]
    size = os.path.getsize(m) / 1e6
    print(f"| {name} | {size:.2f} MB | {t_e:.3f} | {t_o:.3f} | {t_e / t_o:.1f}x | {m_e:.0f} | {m_o:.0f} | {m_o / m_e:.2f} |")
EOF
