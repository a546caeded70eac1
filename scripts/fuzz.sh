#!/usr/bin/env bash
# Fuzzes the two readers of user files with libFuzzer (clang, ASan + UBSan): the configuration reader
# (fuzz/fuzz_config.cpp) and the Gmsh mesh reader (fuzz/fuzz_mesh.cpp), SECONDS each (default 300), one process each.
# New inputs go to build/fuzz/work/; at the end the ones that add coverage are merged into fuzz/corpus/{config,mesh}/
# (replayed by tests/test_robustness_corpus.cpp). A finding (crash, sanitizer report, leak, timeout, uncaught
# exception, multi-line message) stops that target; its input is saved as build/fuzz/artifacts/TARGET-*.
# Usage: scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
bash scripts/install-deps.sh
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j 2
status=0
for target in config mesh; do
  work=build/fuzz/work/$target
  mkdir -p "$work" build/fuzz/artifacts
  echo "fuzz: $target for $seconds s"
  if ! build/fuzz/fuzz/fuzz_$target "$work" "fuzz/corpus/$target" -dict="fuzz/$target.dict" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 \
      -artifact_prefix="build/fuzz/artifacts/$target-" >"build/fuzz/$target.log" 2>&1; then
    echo "fuzz: $target FOUND A PROBLEM (build/fuzz/$target.log, build/fuzz/artifacts/$target-*)"
    status=1
  fi
  grep -E "^stat::(number_of_executed_units|peak_rss_mb)|^Done [0-9]+ runs" "build/fuzz/$target.log" || true
  build/fuzz/fuzz/fuzz_$target -merge=1 "fuzz/corpus/$target" "$work" >"build/fuzz/$target.merge.log" 2>&1
  echo "fuzz: corpus fuzz/corpus/$target: $(ls "fuzz/corpus/$target" | wc -l) files"
done
exit $status
