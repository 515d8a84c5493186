#!/usr/bin/env bash
# Regenerates the accuracy-against-cost charts of docs/charts/ (issue 6): for each validation
# problem, `mbd study` runs HHT at two alphas, generalized-alpha and time finite elements over a
# range of steps, and writes the study's CSV, its SVG chart (and a PNG of it) and its printed
# report (observed orders, CPU time to reach relative errors 1e-3 and 1e-6).
# Usage: docs/charts/make.sh   (from anywhere; builds the release binary first)
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet --bin mbd --example svg_to_png
mbd=target/release/mbd
out=docs/charts
integrators=hht:-0.1,hht:-0.3,generalized-alpha,fet

study() {
    local name=$1
    shift
    "$mbd" study "$@" --integrator "$integrators" -o "$out/$name.csv" --chart "$out/$name.svg" \
        | tee "$out/$name.txt"
}

# P1, the paper's Fig. 6: the rotating beam's angle after half a turn against phi = Omega t.
study p1_rotating_beam models/rotating_beam.mbd --channel phi --at 0.032001554992256216 \
    --reference exact --steps 12,18,36,90,180,360,720
# P2: the pendulum's x over 1 s against the finest run (a quarter of the smallest step).
study p2_pendulum models/pendulum.mbd --channel x --steps 50,100,200,400,800,1600,3200
# P3: the two-bar's bar-2 centre of mass (z) over the first 10 s (loads ramping up, bar 2
# spinning up through several turns), and over the problem's 50 s (64 turns: phase errors
# dominate until small steps).
study p3_two_bar_10s models/two_bar.mbd --channel zc2 --until 10 --steps 200,400,800,1600,3200,6400
study p3_two_bar_50s models/two_bar.mbd --channel zc2 --steps 1000,2000,4000,8000,16000

# PNG beside every SVG (the README shows them).
target/release/examples/svg_to_png "$out"/p[123]_*.svg
