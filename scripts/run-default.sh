#!/usr/bin/env bash
# Installs what is missing, builds the optimized program, and runs the default experiment.
# Until the scenario driver (`immerse run FILE.toml`) lands, the default experiment is the paper's §4.1
# oscillating membrane at a coarse size: forward Euler blows up at dt = 4dx, JFNK relaxes the membrane.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh release
./build/release/immerse verify oscillating_stability --quick
