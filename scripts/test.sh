#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite: first the optimized build,
# then the debug build under AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated
for preset in release debug; do
  bash scripts/build.sh "$preset"
  ctest --preset "$preset"
done
