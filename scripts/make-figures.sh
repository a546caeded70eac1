#!/usr/bin/env bash
# Regenerates every figure in docs/figures/ from the quick scenarios, in one command:
#   bash scripts/make-figures.sh
# Builds the release program if needed, runs (one after another, ~1-2 minutes each)
#   oscillating_membrane_quick at mu = 0.01 and 0.1   (§4.1, Figs. 2-5)
#   capsule_shear_quick at G = 0.0125, 0.05 and 0.1   (§4.2.1, Fig. 7)
# into out/figures/, then plots with Debian's matplotlib (/usr/bin/python3). Each plot script prints its key numbers.
set -euo pipefail
cd "$(dirname "$0")/.."
python=/usr/bin/python3
runs=out/figures
figs=docs/figures
mkdir -p "$runs" "$figs"

[[ -f build/release/CMakeCache.txt ]] || cmake --preset release >/dev/null
cmake --build build/release -j2 >/dev/null
immerse=build/release/immerse

run() { # run SCENARIO OUTDIR [--set key=value ...]
  local scenario=$1 out=$2
  shift 2
  echo "== $scenario -> $out $*"
  rm -rf "$out"
  "$immerse" run "scenarios/$scenario.toml" --out "$out" "$@" > "$out.log" 2>&1 || {
    echo "immerse run failed, see $out.log:"; tail -5 "$out.log"; exit 1; }
  tail -2 "$out.log"
}

run oscillating_membrane_quick "$runs/osc_mu0.01" --set fluid.mu=0.01
run oscillating_membrane_quick "$runs/osc_mu0.1" --set fluid.mu=0.1
for G in 0.0125 0.05 0.1; do
  run capsule_shear_quick "$runs/shear_G$G" --set scenario.G=$G
done

$python scripts/plot_iterations.py "$runs/osc_mu0.01" -o "$figs/fig2_iterations.png"
$python scripts/plot_shapes.py "$runs/osc_mu0.01" --frames 0,1,2,10 -o "$figs/fig3_shapes.png"
$python scripts/plot_semi_axes.py "$runs/osc_mu0.01" -o "$figs/fig4_semi_axes_mu0.01.png"
$python scripts/plot_semi_axes.py "$runs/osc_mu0.1" -o "$figs/fig5_semi_axes_mu0.1.png"
$python scripts/plot_taylor.py "$runs"/shear_G0.0125 "$runs"/shear_G0.05 "$runs"/shear_G0.1 -o "$figs/fig7_taylor.png"
