#!/usr/bin/env bash
# Builds the Debian package target/debian/slipgate_VERSION_ARCH.deb: the `slipgate` command and
# each stage's own binary (slipgate-bsp, -vis, -light, -view), depending on Debian's Embree 3.
# Needs scripts/deps.sh's packages and cargo-deb (`cargo install cargo-deb`, installed here when
# missing). Install the result with `apt install ./target/debian/slipgate_*.deb`.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! cargo deb --version >/dev/null 2>&1; then
  cargo install --locked cargo-deb
fi
cargo build --release --workspace --bins
cargo deb --no-build --strip
