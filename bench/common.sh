# Sourced by the bench scripts: `root` (this tree), `corpus` (../shared/corpus beside it),
# `anchor_bin` (ericw-tools' binaries, ../shared/anchors/ericw-tools/bin), and `slipgate_binary`,
# which prints the `slipgate` to measure: $SLIPGATE when set (another build), else this tree's
# release build, built first.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
corpus="$root/../shared/corpus"
anchor_bin="$root/../shared/anchors/ericw-tools/bin"
slipgate_binary() {
  if [ -n "${SLIPGATE:-}" ]; then
    echo "$SLIPGATE"
  else
    cargo build --release --manifest-path "$root/Cargo.toml" -p slipgate >/dev/null
    echo "${CARGO_TARGET_DIR:-$root/target}/release/slipgate"
  fi
}
