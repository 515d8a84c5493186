#!/usr/bin/env bash
# Side-by-side benchmark of mbd against Exudyn (issue 20, item 6). Not part of .ci/run.
# Usage: bash benches/peers/run.sh [--quick] [--only NAME] [--cli]     (from anywhere)
# MBD=path/to/mbd overrides the binary (default: target/release/mbd; build it first with
# `cargo build --release`; the script reads its version, and `--cli` times it). Builds mbd's
# Python package from this checkout into the venv, which the script times in its process.
# Creates benches/peers/.venv with Exudyn from PyPI on first use and writes
# benches/peers/out/ (summary.md, ladder.csv, one PNG per problem).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
export MBD="${MBD:-$root/target/release/mbd}"
if [ ! -x "$MBD" ]; then
    echo "no mbd binary at $MBD: run \`cargo build --release\` first, or set MBD" >&2
    exit 2
fi
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import exudyn, numpy, matplotlib" 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip
    "$venv/bin/pip" install --quiet exudyn==1.13.6 numpy matplotlib
fi
# mbd's own Python package from this checkout, rebuilt each time (cargo's target/python keeps
# the build between runs, as tests/python.rs does): the script times mbd in its process, as
# it times Exudyn. `--cli` times the binary instead.
if ! "$venv/bin/python" -c "import maturin" 2>/dev/null; then
    "$venv/bin/pip" install --quiet "maturin>=1.5,<2"
fi
(cd "$root" && PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$root/target/python" \
    "$venv/bin/pip" install --quiet --disable-pip-version-check --no-build-isolation \
    --force-reinstall --no-deps .)
exec "$venv/bin/python" "$here/peers.py" "$@"
