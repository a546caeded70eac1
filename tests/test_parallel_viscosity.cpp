// Tests of the viscosity contrast on slabs, run by ctest through mpiexec with 1, 2 and 3 processes (tests
// ParallelViscosity.np1/np2/np3): the interior indicator χ (SlabViscosityIndicator) gathered from the processes against
// the whole-grid ViscosityIndicator, and five variable-viscosity steps of SlabNavierStokesSolver against
// NavierStokesSolver's; both repeated bitwise.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "MpiEnvironment.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/coupling/SlabViscosityIndicator.hpp"
#include "immerse/coupling/ViscosityIndicator.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/parallel/HaloExchange.hpp"
#include "immerse/parallel/MembraneOwnership.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double kTwoPi = 2 * std::numbers::pi;

double max_abs(const Array3& a) {
  double m = 0;
  for (double v : a.values()) m = std::max(m, std::abs(v));
  return m;
}

double max_abs_difference(const Array3& a, const Array3& b) {
  EXPECT_EQ(a.shape(), b.shape());
  double m = 0;
  for (std::size_t q = 0; q < std::min(a.size(), b.size()); ++q) m = std::max(m, std::abs(a[q] - b[q]));
  return m;
}

double relative_difference(const FaceField& a, const FaceField& b) {
  double diff = 0, scale = 0;
  for (int d = 0; d < 3; ++d) {
    diff = std::max(diff, max_abs_difference(a[d], b[d]));
    scale = std::max(scale, max_abs(b[d]));
  }
  return diff / scale;
}

// ---- The indicator ----

// 16 x 12 x 15 cells of h = 0.1, periodic x and y: along z slabs of 8/7 cell planes on 2 processes and 5/5/5 on 3.
Grid indicator_grid(Boundary z) { return Grid({16, 12, 15}, {1.6, 1.2, 1.5}, {P, P, z}); }

struct Sphere {
  Vec3 centre;
  double radius, ratio;
};

// Spheres of λ = 5 and 0.2 across the slab boundaries (z = 0.5, 0.8, 1.0), the periodic x and y boundaries, within
// a cell of the z walls, and (periodic z) across the periodic z boundary.
std::vector<Sphere> spheres(const Grid& g) {
  std::vector<Sphere> s{
      {{0.4, 0.35, 0.3}, 0.21, 5.0},    // 0.09 from the lower wall
      {{1.0, 0.7, 0.72}, 0.3, 5.0},     // across z = 0.5 and 0.8
      {{1.45, 1.0, 1.02}, 0.25, 0.2},   // across the periodic x and y boundaries, z = 0.8 and 1.0
      {{0.35, 0.55, 1.22}, 0.2, 5.0},   // 0.08 from the upper wall
      {{1.2, 0.2, 0.35}, 0.15, 1.0},    // no contrast: contributes nothing
  };
  if (g.periodic(2)) s.push_back({{0.8, 0.9, 1.45}, 0.25, 0.2});  // nodes up to z = 1.7
  return s;
}

TEST(ParallelViscosity, IndicatorEqualsTheSerialOneAndRepeatsBitwise) {
  const Communicator comm = Communicator::world();
  const Mesh sphere = icosahedral_sphere(2);
  for (const Boundary z : {W, P}) {
    const Grid g = indicator_grid(z);
    const std::vector<Sphere> list = spheres(g);
    std::vector<std::vector<Vec3>> X;
    std::vector<double> ratio;
    for (const Sphere& s : list) {
      X.emplace_back();
      for (const Vec3& x : sphere.nodes) X.back().push_back(s.centre + x * s.radius);
      ratio.push_back(s.ratio);
    }
    for (const DeltaKernel kernel : {DeltaKernel{RomaPeskin3{}}, DeltaKernel{Peskin4{}}}) {
      const std::string name = std::string(z == W ? "z walls" : "periodic z") + ", kernel " +
                               (std::holds_alternative<RomaPeskin3>(kernel) ? "roma3" : "peskin4");
      IBCoupler serial_coupler(g, kernel);
      ViscosityIndicator serial(serial_coupler);
      std::vector<IndicatorSurface> surfaces;
      for (std::size_t m = 0; m < X.size(); ++m) surfaces.push_back({&sphere.elements, &X[m], ratio[m]});
      Array3 expected;
      serial.compute(surfaces, expected);

      const SlabDecomposition slabs(g, comm);
      SlabIBCoupler coupler(slabs, kernel);
      const MembraneOwnership owners(slabs, X, X);
      const auto compute = [&](SlabViscosityIndicator& indicator) {
        std::vector<OwnedIndicatorSurface> mine;
        for (const OwnedMembrane& m : owners.owned()) mine.push_back({m.id, &sphere.elements, &m.positions});
        Array3 chi;
        indicator.compute(mine, chi);
        return chi;
      };
      SlabViscosityIndicator indicator(coupler, ratio);
      const Array3 chi = compute(indicator);
      EXPECT_EQ(indicator.target_integral(), serial.target_integral()) << name;  // the same sum in the same order
      const Array3 result = slabs.gather(chi, Layout::Pressure);
      const double diff = max_abs_difference(result, expected) / max_abs(expected);
      EXPECT_LE(diff, 1e-12) << name;
      EXPECT_GT(max_abs(expected), 3.9) << name;  // the λ = 5 interiors
      // χ takes both signs (λ = 5 and 0.2) and vanishes away from the membranes.
      const auto [lo, hi] = std::ranges::minmax(expected.values());
      EXPECT_LT(lo, -0.7) << name;
      EXPECT_GT(hi, 3.9) << name;
      EXPECT_GT(std::ranges::count(expected.values(), 0.0), static_cast<long>(expected.size() / 2)) << name;
      // The ghost planes hold the neighbours' planes (or the copy of the cell inside beyond a wall).
      Array3 refilled = chi;
      HaloExchange(slabs, Vec3{}, Vec3{}).exchange(refilled, Layout::Pressure);
      EXPECT_EQ(refilled.values(), chi.values()) << name;
      // Repeated, and by a new indicator: the same bits.
      EXPECT_EQ(compute(indicator).values(), chi.values()) << name;
      SlabViscosityIndicator fresh(coupler, ratio);
      EXPECT_EQ(compute(fresh).values(), chi.values()) << name;
      if (comm.rank() == 0)
        std::printf("[ParallelViscosity] %d processes, %s: indicator max relative difference to the serial one "
                    "%.2e (max chi %.4f, min %.4f)\n",
                    comm.size(), name.c_str(), diff, hi, lo);
    }
  }
}

// ---- The variable-viscosity fluid step ----

// 12 x 10 x 9 cells of h = 0.1 (slabs of 5/4 cell planes on 2 processes, 3/3/3 on 3), as ParallelFluidStep.
Grid fluid_grid(const std::array<Boundary, 3>& bc) { return Grid({12, 10, 9}, {1.2, 1.0, 0.9}, bc); }

struct Case {
  std::string name;
  std::array<Boundary, 3> bc;
  FluidParams params;
};

std::array<Case, 3> cases() {
  FluidParams periodic;
  periodic.rho = 1.0;
  periodic.mu = 0.05;
  periodic.body_force = {0.3, 0.0, -0.1};
  periodic.variable_viscosity = true;
  periodic.implicit_ratio = 3.0;
  FluidParams couette = periodic;  // z walls moving along x in opposite directions
  couette.body_force = {};
  couette.wall_lower[2] = {-0.5, 0.0, 0.0};
  couette.wall_upper[2] = {0.5, 0.0, 0.0};
  FluidParams channel = periodic;  // walls along x and z, flow along y, the extrapolated pressure
  channel.mu = 0.2;
  channel.body_force = {0.0, 1.0, 0.0};
  channel.pressure = PressurePredictor::Extrapolated;
  channel.wall_upper[0] = {0.0, 0.3, 0.0};  // the upper x wall slides along y
  return {Case{"periodic box", {P, P, P}, periodic}, Case{"moving z walls", {P, P, W}, couette},
          Case{"channel (walls along x and z)", {W, P, W}, channel}};
}

FluidState initial_state(const NavierStokesSolver& serial) {
  const Grid& g = serial.grid();
  const double lx = g.length(0), ly = g.length(1), lz = g.length(2);
  FluidState s = serial.initial_state();
  sample_velocity(
      g,
      [&](const Vec3& x) {
        const double a = kTwoPi * x[0] / lx, b = kTwoPi * x[1] / ly, c = kTwoPi * x[2] / lz;
        return Vec3{0.6 * std::sin(b) * std::cos(c) + 0.2 * std::cos(a), 0.5 * std::sin(c) * std::cos(a) + 0.1,
                    0.4 * std::sin(a) * std::cos(b)};
      },
      s.u);
  serial.apply_wall_values(s.u);
  return s;
}

FaceField body_force(const Grid& g) {
  const double lx = g.length(0), ly = g.length(1), lz = g.length(2);
  FaceField f;
  sample_velocity(
      g,
      [&](const Vec3& x) {
        const double a = kTwoPi * x[0] / lx, b = kTwoPi * x[1] / ly, c = kTwoPi * x[2] / lz;
        return Vec3{0.3 * std::cos(c) * std::sin(a), 0.2 * std::sin(b) + 0.1 * std::cos(a), 0.1 * std::cos(a + b)};
      },
      f);
  return f;
}

// χ in [0, 2] (μ ≤ 3 μ = μ_p), zero on about half of the cells, non-zero up to the walls and on the slab boundaries;
// a different field at each step n.
Array3 viscosity_field(const Grid& g, int n) {
  Array3 chi(g.n(0), g.n(1), g.n(2));
  for (int k = 0; k < g.n(2); ++k)
    for (int j = 0; j < g.n(1); ++j)
      for (int i = 0; i < g.n(0); ++i) {
        const double a = kTwoPi * (i + 0.5) / g.n(0), b = kTwoPi * (j + 0.5) / g.n(1), c = kTwoPi * (k + 0.5) / g.n(2);
        chi(i, j, k) = std::max(0.0, 2.0 * std::sin(a + 0.2 * n) * std::cos(b - 0.3) * std::cos(0.5 * c + 0.1 * n));
      }
  return chi;
}

constexpr int kSteps = 5;
double step_size(int n) { return 0.01 * (1.0 + 0.1 * n); }  // a varying step: AB2, p̃ and ũ with r ≠ 1

FluidState run_serial(NavierStokesSolver& serial, FluidState s, const FaceField& force) {
  FluidState next;
  for (int n = 0; n < kSteps; ++n) {
    const Array3 chi = viscosity_field(serial.grid(), n);
    serial.step(s, force, step_size(n), next, &chi);
    std::swap(s, next);
  }
  return s;
}

FluidState run_slabs(SlabNavierStokesSolver& slab, const FluidState& start, const FaceField& force) {
  const SlabDecomposition& slabs = slab.decomposition();
  const HaloExchange halo(slabs, Vec3{}, Vec3{});
  FluidState s = slab.scatter(start), next;
  const FaceField f = slab.scatter(force);
  for (int n = 0; n < kSteps; ++n) {
    Array3 chi;
    slabs.scatter(viscosity_field(slab.grid(), n), Layout::Pressure, chi);
    halo.exchange(chi, Layout::Pressure);
    slab.step(s, f, step_size(n), next, &chi);
    std::swap(s, next);
  }
  return slab.gather(s);
}

bool bitwise_equal(const FluidState& a, const FluidState& b) {
  bool same = a.p.values() == b.p.values() && a.p_prev.values() == b.p_prev.values();
  for (int d = 0; d < 3; ++d)
    same = same && a.u[d].values() == b.u[d].values() && a.adv[d].values() == b.adv[d].values() &&
           a.u_prev[d].values() == b.u_prev[d].values();
  return same;
}

}  // namespace

TEST(ParallelViscosity, VariableViscosityStepsEqualTheSerialStepsAndRepeatBitwise) {
  const Communicator comm = Communicator::world();
  for (const Case& c : cases()) {
    const Grid g = fluid_grid(c.bc);
    NavierStokesSolver serial(g, c.params, FftPlanning::Estimate);
    const FluidState start = initial_state(serial);
    const FaceField force = body_force(g);
    const FluidState expected = run_serial(serial, start, force);
    // The contrast matters: the same steps with a constant viscosity μ end elsewhere.
    FluidParams constant = c.params;
    constant.variable_viscosity = false;
    constant.implicit_ratio = 1.0;
    NavierStokesSolver plain(g, constant, FftPlanning::Estimate);
    FluidState s = start, next;
    for (int n = 0; n < kSteps; ++n) {
      plain.step(s, force, step_size(n), next);
      std::swap(s, next);
    }
    EXPECT_GT(relative_difference(s.u, expected.u), 1e-3) << c.name;

    SlabNavierStokesSolver slab(g, c.params, comm);
    const FluidState result = run_slabs(slab, start, force);
    EXPECT_EQ(result.step, kSteps);
    const double du = relative_difference(result.u, expected.u);
    const double dadv = relative_difference(result.adv, expected.adv);
    const double dprev = relative_difference(result.u_prev, expected.u_prev);
    const double dp = max_abs_difference(result.p, expected.p) / max_abs(expected.p);
    EXPECT_LE(du, 1e-12) << c.name;
    EXPECT_LE(dadv, 1e-12) << c.name;
    EXPECT_LE(dprev, 1e-12) << c.name;
    EXPECT_LE(dp, 1e-12) << c.name;
    Array3 div;
    divergence(g, result.u, div);
    const double max_div = max_abs(div);
    EXPECT_LE(max_div, 1e-12) << c.name;

    EXPECT_TRUE(bitwise_equal(run_slabs(slab, start, force), result)) << c.name;
    SlabNavierStokesSolver fresh(g, c.params, comm);
    EXPECT_TRUE(bitwise_equal(run_slabs(fresh, start, force), result)) << c.name;
    if (comm.rank() == 0)
      std::printf("[ParallelViscosity] %d processes, %s: variable-viscosity steps, max relative difference to the "
                  "serial step u %.2e, p %.2e, (u.grad u) %.2e; max |D u| %.2e\n",
                  comm.size(), c.name.c_str(), du, dp, dadv, max_div);
  }
}
