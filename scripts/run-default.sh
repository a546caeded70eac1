#!/usr/bin/env bash
# Installs what is missing, builds the optimized program, and runs the default experiment.
# The default experiment is the quick §4.2.1 capsule in shear flow (a coarse version of the paper's Fig. 7):
# it prints the Taylor deformation D_xz it reached (small-deformation theory: 25G/4 = 0.31 at G = 0.05).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh release
./build/release/immerse run scenarios/capsule_shear_quick.toml --out out/capsule_shear_quick --overwrite
