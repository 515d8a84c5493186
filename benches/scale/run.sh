#!/usr/bin/env bash
# The compiler's cost against model size (issue 21): wall time and peak memory of `mbd check`
# on generated models, each the median of 3 runs. Not part of .ci/run.
#   bash benches/scale/run.sh            # chains of 10 to 100,000 links, a closed loop of
#                                        # 2,000, 20,000 and 200,000 unused params
# Needs python3 (to write the models) and GNU time (/usr/bin/time).
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
mbd=target/release/mbd
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
shipped = open("models/chain.mbd").read()
def chain(n, extra=""):
    return shipped.replace("param links = 100", f"param links = {n}") + extra + "\n"
for n in [10, 100, 400, 1000, 10000, 100000]:
    open(f"{d}/chain {n} links.mbd", "w").write(chain(n))
open(f"{d}/closed loop 2000 links.mbd", "w").write(
    chain(2000, "joint close = revolute(earth @ (200, 0, 0) m, rod[2000].end) { axis = z }"))
for n in [20000, 200000]:
    head = "model p\nground earth\npoint_mass bob { mass = 1 kg, at = (0, -1, 0) m }\njoint rope = distance(earth, bob)\n"
    open(f"{d}/{n} unused params.mbd", "w").write(
        head + "".join(f"param p{i} = {i}\n" for i in range(n)) + "solve hht { dt = 1 ms, until = 1 s }\n")
PY
printf '%-28s %10s %12s\n' model 'wall [s]' 'peak [MB]'
for f in "$dir"/chain*.mbd "$dir"/closed*.mbd "$dir"/*params.mbd; do
    runs=()
    for k in 1 2 3; do
        /usr/bin/time -o "$dir/time" -f '%e %M' "$mbd" check "$f" >/dev/null 2>&1 || true
        runs+=("$(tail -1 "$dir/time")")
    done
    median=$(printf '%s\n' "${runs[@]}" | sort -n | sed -n 2p)
    printf '%-28s %10s %12.0f\n' "$(basename "$f" .mbd)" "${median% *}" "$(( ${median#* } / 1024 ))"
done
