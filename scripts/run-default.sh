#!/usr/bin/env bash
# Installs what is missing, builds the optimized program, and runs the default experiment.
# Until the scenario driver lands (see README), the default experiment is the fluid solver's Taylor-Green study.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh release
./build/release/immerse verify taylor_green
