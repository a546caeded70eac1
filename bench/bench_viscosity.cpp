// Cost of a viscosity contrast in one fluid step (docs/viscosity-contrast.md): a sphere of radius a (10,242 nodes)
// in a 64³ box of side 10a with walls along z, the paper's shear-flow case (§4.2.1), λ = 5 against λ = 1.
//
// trial: what each evaluation of an implicit step's residual pays, NavierStokesSolver::step(prepared, F) and, with
// λ = 5, the indicator χ of the midpoint positions (ViscosityIndicator::compute) and the stress term.
// step: prepare() plus one trial (an explicit step).
// Each is timed as the fastest of the benchmark loop's repetitions (robust to other processes sharing the machine);
// the counters trial_ratio and step_ratio are λ = 5 over λ = 1.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/ViscosityIndicator.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/MeshGenerator.hpp"

using namespace immerse;

namespace {

struct Case {
  Grid grid{{64, 64, 64}, {10, 10, 10}, {Boundary::Periodic, Boundary::Periodic, Boundary::Wall}};
  Mesh mesh = icosahedral_sphere(4);
  std::vector<Vec3> X;
  FaceField force{grid};
  Case() {
    for (const Vec3& p : mesh.nodes) X.push_back(Vec3{5, 5, 5} + p);
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal;
    for (int d = 0; d < 3; ++d)
      for (auto& v : force[d].values()) v = normal(rng);
  }
};

/// Fastest seconds of a trial and of a whole step with viscosity ratio lambda, over `reps` repetitions each.
std::pair<double, double> time_step(const Case& c, double lambda, int reps) {
  FluidParams prm;
  prm.variable_viscosity = lambda != 1.0;
  prm.implicit_ratio = std::max(1.0, lambda);
  NavierStokesSolver ns(c.grid, prm, FftPlanning::Estimate);
  IBCoupler coupler(c.grid);
  ViscosityIndicator indicator(coupler);
  FluidState s0 = ns.initial_state(), s1, s2;
  PreparedStep prepared;
  Array3 chi;
  const IndicatorSurface surface{&c.mesh.elements, &c.X, lambda};
  // Two steps first, so that the timed ones extrapolate from u^{n-1} as in a run.
  ns.step(s0, c.force, 0.01, s1);
  ns.step(s1, c.force, 0.01, s2);
  const auto trial = [&] {
    if (prm.variable_viscosity) indicator.compute({&surface, 1}, chi);
    ns.step(prepared, c.force, s1, prm.variable_viscosity ? &chi : nullptr);
  };
  double best_trial = INFINITY, best_step = INFINITY;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    ns.prepare(s2, 0.01, prepared);
    const auto t1 = std::chrono::steady_clock::now();
    trial();
    const auto t2 = std::chrono::steady_clock::now();
    best_trial = std::min(best_trial, std::chrono::duration<double>(t2 - t1).count());
    best_step = std::min(best_step, std::chrono::duration<double>(t2 - t0).count());
    benchmark::DoNotOptimize(s1.u[0].data());
  }
  return {best_trial, best_step};
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const int max_threads = std::min(2, omp_get_max_threads());
  for (int t = 1; t <= max_threads; ++t)
    benchmark::RegisterBenchmark(("fluid_step_lambda5_over_lambda1/threads:" + std::to_string(t)).c_str(),
                                 [t](benchmark::State& state) {
                                   omp_set_num_threads(t);
                                   const Case c;
                                   std::pair<double, double> one{INFINITY, INFINITY}, five = one;
                                   for (auto _ : state) {
                                     const auto a = time_step(c, 1.0, 5), b = time_step(c, 5.0, 5);
                                     one = {std::min(one.first, a.first), std::min(one.second, a.second)};
                                     five = {std::min(five.first, b.first), std::min(five.second, b.second)};
                                   }
                                   state.counters["trial_s_lambda1"] = one.first;
                                   state.counters["trial_s_lambda5"] = five.first;
                                   state.counters["trial_ratio"] = five.first / one.first;
                                   state.counters["step_s_lambda1"] = one.second;
                                   state.counters["step_s_lambda5"] = five.second;
                                   state.counters["step_ratio"] = five.second / one.second;
                                 })
        ->Iterations(2)
        ->Unit(benchmark::kSecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
