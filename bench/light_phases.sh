#!/usr/bin/env bash
# Where light's work goes: instruction counts (callgrind, one thread) of each phase of a light
# run, for one or more builds of `slipgate`, side by side. Instructions are the stable measure on
# a shared machine; bench/light_side_by_side.sh gives wall times against ericw-tools.
# bench/results/light-phases.md comes from this.
#
# Usage: [OPTS="--extra4 --soft"] bench/light_phases.sh MAP.bsp LABEL=SLIPGATE_BINARY...
# (a lit or unlit, vised BSP; nothing is written beside it). OPTS are light's options, e.g.
# OPTS="--face-stride 8 --extra4 --soft" to time every 8th face of a large map.
# Prints a Markdown table: one row per phase, one column per build, in G instructions.
set -euo pipefail
[ $# -ge 2 ] || { sed -n '2,10s/^# \{0,1\}//p' "$0"; exit 2; }
command -v valgrind >/dev/null || { echo "SKIPPED: valgrind not found" >&2; exit 0; }
bsp=$1; shift
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
export RAYON_NUM_THREADS=1
labels=()
for spec in "$@"; do
  label=${spec%%=*}; bin=${spec#*=}
  labels+=("$label")
  cp "$bsp" "$work/$label.bsp"
  # Run where no source path resolves: from the workspace, callgrind records relative source
  # paths and callgrind_annotate then splits inlined functions' inclusive counts differently.
  bin=$(realpath "$bin")
  # shellcheck disable=SC2086 # the option string is split on purpose
  (cd "$work" && valgrind --tool=callgrind --callgrind-out-file="$label.out" \
    "$bin" light --threads 1 ${OPTS:-} "$label.bsp" >"$label.log" 2>&1)
  (cd "$work" && callgrind_annotate --inclusive=yes "$label.out" >"$label.txt" 2>/dev/null)
done
# Each phase by the function that holds it, inclusive of what it calls (older builds named some
# differently: the first pattern found counts).
python3 - "$work" "${labels[@]}" <<'PY'
import re, sys
work, labels = sys.argv[1], sys.argv[2:]
phases = [
    ("whole run", [r"PROGRAM TOTALS"]),
    ("setup: BSP checks, Embree scene, lights", [r"light::prepare::prepare \[", r"light::prepare \["]),
    ("sample points: placement, solid test, nudges", [r"light::samples::face_samples \["]),
    ("  of which placement on the face", [r"light::samples::SurfaceMap::place \["]),
    ("direct light: lights, suns, shadow rays", [r"light::trace::trace_face \["]),
    ("  of which Embree's ray queries", [[r"light::embree::Scene::occluded16 \[",
                                          r"light::embree::Scene::first_hits16 \["]]),
    ("  of which dirt (ambient occlusion)", [r"light::dirt::adaptive::face_occlusion \[",
                                             r"light::dirt::adaptive::Measured::measure \["]),
    ("samples to luxels: fill, --soft blur, means", [r"light::luxels::ericw_luxels \["]),
    ("bytes and lumps", [r"light::run::finish_lighting \[", r"light::finish_lighting \[",
                         [r"light::output::finish_face \[", r"light::output::write_lighting \["]]),
]
def one(text, pattern):
    for line in text.splitlines():
        if re.search(pattern, line) and "=>" not in line:
            return int(line.split()[0].replace(",", ""))
    return None

def count(text, patterns):
    """The first pattern found; a list of patterns in one entry counts their sum."""
    for p in patterns:
        found = [one(text, q) for q in (p if isinstance(p, list) else [p])]
        if any(n is not None for n in found):
            return sum(n or 0 for n in found)
    return None
texts = {l: open(f"{work}/{l}.txt").read() for l in labels}
print("| phase | " + " | ".join(labels) + " |")
print("|---|" + "---|" * len(labels))
for name, patterns in phases:
    cells = []
    for l in labels:
        n = count(texts[l], patterns)
        cells.append("—" if n is None else f"{n / 1e9:.2f}")
    print(f"| {name} | " + " | ".join(cells) + " |")
PY
