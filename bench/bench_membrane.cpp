// Membrane force evaluations on the level-4 icosahedral sphere (10,242 nodes, 5,120 six-node elements):
// elements per second per core for both force methods, with and without bending, on 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <chrono>
#include <ctime>

#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/MeshGenerator.hpp"

using namespace immerse;

namespace {

void BM_MembraneForce(benchmark::State& state) {
  const auto method = state.range(0) == 0 ? ForceMethod::Contour : ForceMethod::Energy;
  const double kappa_B = state.range(1) ? 0.05 : 0.0;
  const int threads = static_cast<int>(state.range(2));
  const Mesh mesh = icosahedral_sphere(4);
  const ElasticMembrane m(mesh, mesh.nodes, Skalak{0.2, 2.0}, {kappa_B, ReferenceCurvature::RestShape}, method);
  std::vector<Vec3> X(mesh.nodes.size()), F;
  for (std::size_t i = 0; i < X.size(); ++i) {
    const Vec3 p = mesh.nodes[i];
    X[i] = {1.2 * p.x, 0.9 * p.y, 0.85 * p.z};
  }
  using clock = std::chrono::steady_clock;
  auto wall = [&](int n) {
    const auto t0 = clock::now();
    for (int k = 0; k < n; ++k) m.compute_force(X, F);
    return std::chrono::duration<double>(clock::now() - t0).count() / n;
  };
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const double t1 = wall(5);  // one-thread wall time per evaluation, for the speedup counter
  omp_set_num_threads(threads);
  double tn = 0;
  for (auto _ : state) {
    const auto t0 = clock::now();
    m.compute_force(X, F);
    tn += std::chrono::duration<double>(clock::now() - t0).count();
    benchmark::DoNotOptimize(F.data());
  }
  omp_set_num_threads(saved);
  const double E = static_cast<double>(m.num_elements());
  // Rate over the process CPU time (all threads): elements per second per core, robust on a shared machine.
  state.counters["elements/s/core"] =
      benchmark::Counter(E * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["speedup"] = t1 / (tn / static_cast<double>(state.iterations()));
  state.counters["bytes/node"] = static_cast<double>(m.memory_bytes()) / static_cast<double>(m.num_nodes());
  state.SetLabel(std::string(method == ForceMethod::Contour ? "contour" : "energy") +
                 (kappa_B > 0 ? "+bending" : ""));
}

// The default force form (-dE/dX of the in-plane and bending energies) against the paper's (eq. 42 with the moments
// of eq. 25) on one thread, with and without bending: counter eq42_over_default = CPU time of eq. (42) / CPU time of
// the default per evaluation (goal >= 1: the default is not slower).
void BM_DefaultAgainstEq42(benchmark::State& state) {
  const double kappa_B = state.range(0) ? 0.05 : 0.0;
  const Mesh mesh = icosahedral_sphere(4);
  const ElasticMembrane energy(mesh, mesh.nodes, Skalak{0.2, 2.0}, {kappa_B, ReferenceCurvature::RestShape},
                               ForceMethod::Energy);
  const ElasticMembrane contour(mesh, mesh.nodes, Skalak{0.2, 2.0}, {kappa_B, ReferenceCurvature::RestShape},
                                ForceMethod::Contour);
  std::vector<Vec3> X(mesh.nodes.size()), F;
  for (std::size_t i = 0; i < X.size(); ++i) X[i] = {1.2 * mesh.nodes[i].x, 0.9 * mesh.nodes[i].y, 0.85 * mesh.nodes[i].z};
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  auto cpu = [] { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; };
  double t_energy = 0, t_contour = 0;
  for (auto _ : state) {  // alternating, so that a slower machine phase hits both
    double t0 = cpu();
    energy.compute_force(X, F);
    t_energy += cpu() - t0;
    t0 = cpu();
    contour.compute_force(X, F);
    t_contour += cpu() - t0;
    benchmark::DoNotOptimize(F.data());
  }
  omp_set_num_threads(saved);
  state.counters["eq42_over_default"] = t_contour / t_energy;
  state.SetLabel(kappa_B > 0 ? "with bending" : "elastic");
}

}  // namespace

BENCHMARK(BM_DefaultAgainstEq42)->Arg(0)->Arg(1)->ArgName("bending")->MeasureProcessCPUTime()->Unit(
    benchmark::kMillisecond);

// Args: method (0 contour, 1 energy), bending (0/1), threads. speedup = 1-thread / n-thread wall time per call.
BENCHMARK(BM_MembraneForce)
    ->ArgsProduct({{0, 1}, {0, 1}, {1, 2}})
    ->ArgNames({"method", "bending", "threads"})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
