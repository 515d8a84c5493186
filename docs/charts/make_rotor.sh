#!/usr/bin/env bash
# Regenerates the rotor charts of docs/charts/ (issue 7): the windmill's (P5) stability band
# against Omega_bar by Floquet and Prony with the multiblade eigenvalues computed independently
# (examples/windmill_mbc.rs) and its Campbell diagram, its lag and hub responses at Omega_bar 1.0 and 2.0 (the paper's
# Figs. 19-21) with the rotor's centre of mass (Fig. 22), and the spin-up (P6, Fig. 24) for
# both torques.
# Usage: docs/charts/make_rotor.sh   (from anywhere; builds the release binary first)
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet --bin mbd --example windmill_mbc --example svg_to_png
mbd=target/release/mbd
out=docs/charts

target/release/examples/windmill_mbc 4 > "$out/p5_mbc.csv"
"$mbd" stability models/windmill.mbd --sweep Omega_bar=0.8:2.6:0.05 --method both \
    --reference "$out/p5_mbc.csv" -o "$out/p5_stability.csv" --chart "$out/p5_stability.svg" \
    | tee "$out/p5_stability.txt"
"$mbd" stability models/windmill.mbd --sweep Omega_bar=0.8:2.6:0.05 --refine 0 \
    --chart-kind campbell -o "$out/p5_campbell.csv" --chart "$out/p5_campbell.svg" > /dev/null
"$mbd" stability models/windmill_elastic.mbd --set elements=2 --sweep Omega_bar=0.8:2.6:0.05 \
    --method both --reference "$out/p5_mbc.csv" -o "$out/p5_elastic_stability.csv" \
    --chart "$out/p5_elastic_stability.svg" | tail -3 > "$out/p5_elastic_stability.txt"

for w in 1.0 2.0; do
    "$mbd" run models/windmill.mbd --set Omega_bar=$w --every 10 -o "$out/p5_windmill_$w.csv"
    units=(--model models/windmill.mbd --set Omega_bar=$w)
    "$mbd" plot "$out/p5_windmill_$w.csv" "${units[@]}" --channel zeta1 --channel zeta2 \
        --channel zeta3 --channel zeta4 --title "P5 lag angles, Omega_bar = $w (Figs. 19-21)" \
        -o "$out/p5_lag_$w.svg"
    "$mbd" plot "$out/p5_windmill_$w.csv" "${units[@]}" --channel x_hub \
        --title "P5 hub displacement, Omega_bar = $w" -o "$out/p5_hub_$w.svg"
    "$mbd" plot "$out/p5_windmill_$w.csv" "${units[@]}" --channel rotor_cm.x \
        --channel rotor_cm.y --title "P5 rotor centre of mass, Omega_bar = $w (Fig. 22)" \
        -o "$out/p5_cm_$w.svg"
done

for t0 in 2500 500; do
    "$mbd" run models/windmill_spinup.mbd --set T0=$t0 --every 10 -o "$out/p6_spinup_$t0.csv"
    units=(--model models/windmill_spinup.mbd --set T0=$t0)
    "$mbd" plot "$out/p6_spinup_$t0.csv" "${units[@]}" --channel Omega_hub \
        --title "P6 rotor speed, T0 = $t0 N m (Fig. 24)" -o "$out/p6_speed_$t0.svg"
    "$mbd" plot "$out/p6_spinup_$t0.csv" "${units[@]}" --channel zeta1 --channel zeta3 \
        --channel zeta_1c --channel zeta_1s --title "P6 lag angles, T0 = $t0 N m (Fig. 24)" \
        -o "$out/p6_lag_$t0.svg"
done

# PNG beside every SVG (the README shows them).
target/release/examples/svg_to_png "$out"/p[56]_*.svg
