#!/usr/bin/env bash
# Installs the Debian packages Slipgate needs (run from anywhere):
#   scripts/deps.sh          to build and run: Embree 3 (libembree-dev) and a C compiler
#   scripts/deps.sh --test   also what the tests play maps with: QuakeSpasm, DarkPlaces, a virtual
#                            display (xvfb, xauth), Mesa's software OpenGL and a font; and, for
#                            the independent light reference, Python's mitsuba and numpy (pip,
#                            for the user when not root; a failed download is a warning, and
#                            the test that needs them says SKIPPED)
# Packages already installed are left alone; apt runs only when one is missing. As root apt runs
# directly, otherwise through sudo. Rust itself comes from rustup (README.md, "Install").
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive

packages=(libembree-dev gcc libc6-dev)
case "${1:-}" in
  "") ;;
  --test) packages+=(quakespasm darkplaces darkplaces-server xvfb xauth libgl1-mesa-dri fonts-dejavu-core
                    python3 python3-pip) ;;
  -h|--help) sed -n '2,7s/^# \{0,1\}//p' "$0"; exit 0 ;;
  *) echo "usage: $0 [--test]" >&2; exit 2 ;;
esac

if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
  echo "error: this script needs Debian's dpkg and apt; install these packages' equivalents yourself: ${packages[*]}" >&2
  exit 1
fi

missing=()
for p in "${packages[@]}"; do
  if [ "$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null)" != "ii " ]; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    as_root=()
  elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo env DEBIAN_FRONTEND=noninteractive)
  else
    echo "error: not root and no sudo: as root, run apt-get install ${missing[*]}" >&2
    exit 1
  fi
  echo "installing: ${missing[*]}" >&2
  "${as_root[@]}" apt-get update -qq
  "${as_root[@]}" apt-get install -y -qq "${missing[@]}"
fi

# bench/independent/reference.py's packages, from PyPI (Debian packages no Mitsuba).
if [ "${1:-}" = --test ] && ! python3 -c "import mitsuba, numpy" >/dev/null 2>&1; then
  pip_args=(install --quiet --disable-pip-version-check)
  [ "$(id -u)" -eq 0 ] || pip_args+=(--user)
  # Debian marks its Python as externally managed; these two packages do not clash with it.
  if python3 -m pip install --help 2>/dev/null | grep -q -- --break-system-packages; then
    pip_args+=(--break-system-packages)
  fi
  echo "installing with pip: mitsuba numpy" >&2
  python3 -m pip "${pip_args[@]}" mitsuba numpy ||
    echo "warning: pip could not install mitsuba and numpy; the independent reference's test will say SKIPPED" >&2
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "note: cargo is not on PATH: install Rust 1.95 or newer from https://rustup.rs (README.md, \"Install\")" >&2
fi
