// Cost of walls of any shape (docs/walls.md): one fluid step in a 32³ periodic box holding a tube of radius 12h
// along z (fluid/GhostCellWalls: two fast solves per Helmholtz problem and a dense triangular solve with the
// capacitance matrix of 2,600 cut points per component), against the same step without the tube. Counter
// ratio_to_step: the fastest step with the tube over the fastest without, taken alternately (goal 1.5). The first
// step with the tube builds and factors the capacitance matrices (reported as setup_s, outside the timing).
// BM_WallSurfaceDistance: φ of a closed surface of 20,480 triangles (walls/WallSurface, its bounding-volume
// hierarchy) at the 32,768 cell centres of a box around it, per point.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/walls/WallGeometry.hpp"
#include "immerse/walls/WallSurface.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic;

template <class F>
double seconds_of(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void BM_FluidStepWithATube(benchmark::State& state) {
  const Grid g({32, 32, 32}, {1, 1, 1}, {P, P, P});
  FluidParams plain;
  plain.rho = 1;
  plain.mu = 0.01;
  plain.body_force = {0, 0, 1};
  FluidParams walled = plain;
  walled.walls = std::make_shared<const WallGeometry>(
      std::vector<WallShape>{{WallShape::Kind::Tube, {0.5, 0.5, 0.5}, {0, 0, 1}, 12.0 / 32, 0, "wall[0]"}}, g);
  NavierStokesSolver a(g, plain, FftPlanning::Estimate), b(g, walled, FftPlanning::Estimate);
  FluidState sa = a.initial_state(), sb = b.initial_state(), out;
  const FaceField force(g);
  const double dt = 0.01;
  const double setup = seconds_of([&] { b.step(sb, force, dt, out); });
  double fastest_plain = 1e30, fastest_walled = 1e30;
  for (auto _ : state) {
    fastest_plain = std::min(fastest_plain, seconds_of([&] { a.step(sa, force, dt, out); }));
    fastest_walled = std::min(fastest_walled, seconds_of([&] { b.step(sb, force, dt, out); }));
  }
  state.counters["ratio_to_step"] = fastest_walled / fastest_plain;
  state.counters["step_ms"] = 1e3 * fastest_walled;
  state.counters["setup_s"] = setup;
}
BENCHMARK(BM_FluidStepWithATube)->Iterations(20)->Unit(benchmark::kMillisecond);

void BM_WallSurfaceDistance(benchmark::State& state) {
  const Mesh sphere = icosahedral_sphere(5);
  std::vector<Vec3> v;
  for (const Vec3& x : sphere.nodes) v.push_back(0.6 * x + Vec3{1, 1, 1});
  std::vector<std::array<int, 3>> t;
  for (const auto& e : sphere.elements)
    for (const auto& tri : {std::array<int, 3>{e[0], e[3], e[5]}, std::array<int, 3>{e[3], e[1], e[4]},
                            std::array<int, 3>{e[5], e[4], e[2]}, std::array<int, 3>{e[3], e[4], e[5]}})
      t.push_back(tri);
  const auto surface = std::make_shared<const WallSurface>(v, t, "wall[0]");
  const Grid g({32, 32, 32}, {2.0, 2.0, 2.0}, {P, P, P});
  WallShape s;
  s.kind = WallShape::Kind::Surface;
  s.surface = surface;
  s.name = "wall[0]";
  const WallGeometry w({s}, g);
  double sum = 0;
  for (auto _ : state)
    for (int k = 0; k < 32; ++k)
      for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 32; ++i) sum += w.distance(g.cell_position(i, j, k));
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * 32768);
  state.counters["triangles"] = static_cast<double>(t.size());
}
BENCHMARK(BM_WallSurfaceDistance)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
