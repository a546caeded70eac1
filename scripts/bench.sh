#!/usr/bin/env bash
# Builds the optimized programs and runs every benchmark in bench/, then prints one table: benchmark, measured
# figure, its bound, the ratio, the goal (docs/performance.md) and whether it is met. Raw results are kept in
# build/release/bench/results/ (Google Benchmark JSON, and the text of the whole-run benchmarks).
#   bash scripts/bench.sh              all benchmarks (whole runs bench_oscillating and bench_channel at their --quick
#                                      size, the latter's explicit probes limited to 10 minutes: about 15 minutes)
#   bash scripts/bench.sh --paper-size all, and §4.4 at the paper's size too (bench_channel: up to 67 more minutes,
#                                      most of it explicit RK2 runs to t = 0.05 s, limited by --rk2-budget 3600)
#   bash scripts/bench.sh FILTER       only the Google Benchmark cases matching the regex FILTER
# Timings are wall-clock; the ratios are taken inside one program (fastest repetitions of the kernel and of its
# bound), so they stand up to a loaded machine better than the absolute figures, but 2-thread speedups need a
# machine with two idle cores.
set -euo pipefail
cd "$(dirname "$0")/.."
filter=${1:-}
paper=0
if [[ "$filter" == "--paper-size" ]]; then
  paper=1
  filter=""
fi
out=build/release/bench/results
mkdir -p "$out"
rm -f "$out"/*.json "$out"/*.txt
if ! { cmake --preset release && cmake --build --preset release -j 2 --target bench_fluid bench_coupling bench_membrane bench_walls \
         bench_oscillating bench_channel; } >"$out/build.log" 2>&1; then
  cat "$out/build.log" >&2
  exit 1
fi
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start" | tee "$out/machine.txt"
for b in bench_fluid bench_coupling bench_membrane bench_walls; do
  echo "running $b ..." >&2
  args=(--benchmark_format=console --benchmark_out="$out/$b.json" --benchmark_out_format=json)
  [[ -n "$filter" ]] && args+=(--benchmark_filter="$filter")
  "build/release/bench/$b" "${args[@]}" >"$out/$b.txt" 2>&1
done
if [[ -z "$filter" ]]; then
  echo "running bench_oscillating --quick ..." >&2
  build/release/bench/bench_oscillating --quick >"$out/bench_oscillating.txt" 2>&1
  echo "running bench_channel --quick ..." >&2
  build/release/bench/bench_channel --quick --implicit jfnk,anderson --rk2-budget 600 \
    >"$out/bench_channel_quick.txt" 2>&1
fi
if [[ $paper == 1 ]]; then
  echo "running bench_channel (paper size) ..." >&2
  build/release/bench/bench_channel --implicit jfnk,anderson >"$out/bench_channel.txt" 2>&1
fi
echo "load average $(cut -d' ' -f1-3 /proc/loadavg) at end" | tee -a "$out/machine.txt"
/usr/bin/python3 scripts/bench_table.py "$out"
