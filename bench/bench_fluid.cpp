// Cost of one fluid step (paper eqs. 9–13: three Helmholtz solves, one Poisson solve, explicit stencils) on
//   - a 64³ periodic box, and
//   - a 64×128×32 box with walls on y and z, periodic along x,
// with 1 and 2 threads: BM_FluidStep the plain step(in, force, dt, out) (explicit schemes), BM_FluidTrial one trial
// of an implicit step, step(prepared, force, out) after a prepare() made outside the timing (the trials of a step
// share it), BM_FluidEnergy the energy measures every accepted step takes (FluidEnergy.hpp; counter ratio_to_step:
// their time over a plain step's). Counters: ratio_to_transforms = step time / time of the FFTW transforms alone that
// the step performs (4 forward + 4 backward), speedup = (1-thread step time) / (this step time). Both times are the
// fastest of several repetitions, taken alternately, so the ratio is robust to other processes sharing the machine
// (they lengthen some repetitions, rarely all).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <utility>

#include "immerse/fluid/FluidEnergy.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"

using namespace immerse;

namespace {

Grid bench_grid(int which) {
  constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
  if (which == 0) return Grid({64, 64, 64}, {1, 1, 1}, {P, P, P});
  return Grid({64, 128, 32}, {1, 2, 0.5}, {P, W, W});
}

// Seconds of one call of f (one repetition).
template <class F>
double seconds_of(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// 1-thread step time of each (case, grid).
std::map<std::pair<bool, int>, double>& one_thread_step_time() {
  static std::map<std::pair<bool, int>, double> t;
  return t;
}

// One plain step(in, force, dt, out), or (trial) one step(prepared, force, out) after a prepare() outside the timing:
// a trial of an implicit step, which shares the prepared force-independent part with the other trials.
void fluid_case(benchmark::State& state, bool trial) {
  const int which = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  const Grid g = bench_grid(which);
  FluidParams prm;
  prm.rho = 1;
  prm.mu = 0.01;
  prm.body_force = {1, 0, 0};
  prm.wall_upper[2] = {0.5, 0, 0};
  NavierStokesSolver ns(g, prm, FftPlanning::Measure);
  FluidState a = ns.initial_state(), b;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int d = 0; d < 3; ++d)
    for (double& v : a.u[d].values()) v = U(rng);
  ns.apply_wall_values(a.u);
  const FaceField force(g);
  PreparedStep prepared;
  if (trial) ns.prepare(a, 1e-3, prepared);
  const auto one_step = [&] {
    if (trial)
      ns.step(prepared, force, b);
    else
      ns.step(a, force, 1e-3, b);
  };
  one_step();  // first call sizes `b`
  for (auto _ : state) one_step();

  double step = INFINITY, transforms = INFINITY;
  for (int rep = 0; rep < 10; ++rep) {
    step = std::min(step, seconds_of(one_step));
    transforms = std::min(transforms, seconds_of([&] {
                            for (int l = 0; l < 4; ++l) ns.fast_solver(static_cast<Layout>(l)).transform_round_trip();
                          }));
  }
  const std::pair<bool, int> key{trial, which};
  if (threads == 1) one_thread_step_time()[key] = step;
  state.counters["ratio_to_transforms"] = step / transforms;
  if (one_thread_step_time().count(key)) state.counters["speedup"] = one_thread_step_time()[key] / step;
  state.SetLabel(which == 0 ? "64^3 periodic" : "64x128x32, walls y,z");
}

// The energy measures of a random field (the budget's pass over the grid after each accepted step), against a plain
// step on the same grid.
void BM_FluidEnergy(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const Grid g = bench_grid(which);
  FluidParams prm;
  prm.mu = 0.01;
  prm.body_force = {1, 0, 0};
  prm.wall_upper[2] = {0.5, 0, 0};
  NavierStokesSolver ns(g, prm, FftPlanning::Measure);
  FluidState a = ns.initial_state(), b;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int d = 0; d < 3; ++d)
    for (double& v : a.u[d].values()) v = U(rng);
  ns.apply_wall_values(a.u);
  const FaceField force(g);
  ns.step(a, force, 1e-3, b);
  for (auto _ : state) benchmark::DoNotOptimize(fluid_energy(g, prm, a.u, nullptr));
  double energy = INFINITY, step = INFINITY;
  for (int rep = 0; rep < 10; ++rep) {
    energy = std::min(energy, seconds_of([&] { benchmark::DoNotOptimize(fluid_energy(g, prm, a.u, nullptr)); }));
    step = std::min(step, seconds_of([&] { ns.step(a, force, 1e-3, b); }));
  }
  state.counters["ratio_to_step"] = energy / step;
  state.SetLabel(which == 0 ? "64^3 periodic" : "64x128x32, walls y,z");
}

void BM_FluidStep(benchmark::State& state) { fluid_case(state, false); }
void BM_FluidTrial(benchmark::State& state) { fluid_case(state, true); }

}  // namespace

BENCHMARK(BM_FluidStep)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"grid", "threads"})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FluidTrial)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"grid", "threads"})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FluidEnergy)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"grid", "threads"})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
