// Throughput of force spreading (eq. 6) and velocity interpolation (eq. 14): 10,242 nodes on a
// sphere of radius a in a 64³ box of side 10a (the paper's shear-flow case, §4.2.1), 1 and 2
// OpenMP threads, against the streaming-memory bound measured here with a STREAM triad.
//
// Counters: nodes_per_s_per_core = nodes / (wall time × threads). stream_bound_nodes_per_s =
// triad bandwidth / (bytes a node's stencil would move if every grid access went to memory:
// 3 components × width³ points × 16 B read+write for spreading, 8 B read for interpolation).
// fraction_of_stream_bound = achieved nodes/s ÷ that bound (> 1 means caches absorb the stencil
// traffic and the kernel is compute-bound). Both the triad and the kernel are timed as the fastest of many
// repetitions, so the fraction is robust to other processes sharing the machine (they lengthen some
// repetitions, rarely all); nodes_per_s_mean is the mean rate over the benchmark loop, for comparison.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "immerse/coupling/IBCoupler.hpp"

using namespace immerse;

namespace {

constexpr int kNodes = 10242;

std::vector<Vec3> sphere_nodes(int count, Vec3 c, double R) {
  std::vector<Vec3> X(count);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int l = 0; l < count; ++l) {
    const double z = 1.0 - 2.0 * (l + 0.5) / count, r = std::sqrt(1.0 - z * z);
    X[l] = c + R * Vec3{r * std::cos(golden * l), r * std::sin(golden * l), z};
  }
  return X;
}

/// STREAM triad a = b + s c over arrays far larger than the caches, in bytes/s (24 bytes per element, the STREAM
/// convention). The arrays are swept in chunks of 2^20 elements (24 MB, a few ms) and each chunk keeps its fastest
/// of several passes: the bandwidth of an undisturbed sweep even when other processes share the machine.
double triad_bandwidth(int threads) {
  const long n = 1L << 24, chunk = 1L << 20, chunks = n / chunk;
  std::vector<double> a(n), b(n, 1.0), c(n, 2.0);
  omp_set_num_threads(threads);
  std::vector<double> best(chunks, INFINITY);
  for (int rep = 0; rep < 10; ++rep)
    for (long q = 0; q < chunks; ++q) {
      const long lo = q * chunk, hi = lo + chunk;
      const auto t0 = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static)
      for (long i = lo; i < hi; ++i) a[i] = b[i] + 3.0 * c[i];
      best[q] = std::min(best[q], std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      benchmark::DoNotOptimize(a.data());
    }
  double total = 0;
  for (double t : best) total += t;
  return 24.0 * n / total;
}

struct Setup {
  Grid grid{{64, 64, 64}, {10, 10, 10}, {Boundary::Periodic, Boundary::Wall, Boundary::Wall}};
  std::vector<Vec3> X = sphere_nodes(kNodes, {5, 5, 5}, 1.0);
  std::vector<Vec3> F, U = std::vector<Vec3>(kNodes);
  FaceField field{grid};
  Setup() {
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal;
    for (int l = 0; l < kNodes; ++l) F.push_back({normal(rng), normal(rng), normal(rng)});
    for (int d = 0; d < 3; ++d)
      for (auto& v : field[d].values()) v = normal(rng);
  }
};

/// Runs `step` in the benchmark loop and sets the counters described at the top of the file.
template <class Step>
void measure(benchmark::State& state, int threads, double stream_bytes_per_s, double bytes_per_node, Step step) {
  double fastest = INFINITY;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    const auto c0 = std::chrono::steady_clock::now();
    step();
    fastest = std::min(fastest, std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = kNodes / fastest;
  const double bound = stream_bytes_per_s / bytes_per_node;
  state.counters["nodes_per_s"] = rate;
  state.counters["nodes_per_s_mean"] = static_cast<double>(state.iterations()) * kNodes / seconds;
  state.counters["nodes_per_s_per_core"] = rate / threads;
  state.counters["stream_GBps"] = stream_bytes_per_s / 1e9;
  state.counters["stream_bound_nodes_per_s"] = bound;
  state.counters["fraction_of_stream_bound"] = rate / bound;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const int max_threads = std::min(2, omp_get_max_threads());
  std::vector<double> stream(max_threads + 1);
  for (int t = 1; t <= max_threads; ++t) {
    stream[t] = triad_bandwidth(t);
    std::cout << "STREAM triad, " << t << " thread(s): " << stream[t] / 1e9 << " GB/s\n";
  }
  for (const char* name : {"roma3", "peskin4"}) {
    const DeltaKernel kernel = delta_kernel(name);
    const int w = kernel_width(kernel);
    for (int t = 1; t <= max_threads; ++t) {
      benchmark::RegisterBenchmark((std::string("spread_force/") + name + "/threads:" + std::to_string(t)).c_str(),
                                   [=](benchmark::State& state) {
                                     omp_set_num_threads(t);
                                     Setup s;
                                     IBCoupler coupler(s.grid, kernel);
                                     measure(state, t, stream[t], 3.0 * w * w * w * 16 + 48, [&] {
                                       coupler.spread_force(s.X, s.F, s.field);
                                       benchmark::DoNotOptimize(s.field[0].data());
                                     });
                                   })
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(
          (std::string("interpolate_velocity/") + name + "/threads:" + std::to_string(t)).c_str(),
          [=](benchmark::State& state) {
            omp_set_num_threads(t);
            Setup s;
            const IBCoupler coupler(s.grid, kernel);
            measure(state, t, stream[t], 3.0 * w * w * w * 8 + 48, [&] {
              coupler.interpolate_velocity(s.field, s.X, s.U);
              benchmark::DoNotOptimize(s.U.data());
            });
          })
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
