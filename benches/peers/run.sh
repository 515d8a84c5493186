#!/usr/bin/env bash
# Side-by-side benchmark of mbd against Exudyn (issue 20, item 6). Not part of .ci/run.
# Usage: bash benches/peers/run.sh [--quick] [--only NAME]     (from anywhere)
# MBD=path/to/mbd overrides the binary (default: target/release/mbd; build it first with
# `cargo build --release`). Creates benches/peers/.venv with Exudyn from PyPI on first use and
# writes benches/peers/out/ (summary.md, ladder.csv, one PNG per problem).
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
exec "$venv/bin/python" "$here/peers.py" "$@"
