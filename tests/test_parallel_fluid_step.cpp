// Tests of the slab-decomposed fluid step, run by ctest through mpiexec with 1, 2 and 3 processes (tests
// ParallelFluidStep.np1/np2/np3): the ghost planes of the halo exchange, and five steps of SlabNavierStokesSolver
// gathered from every process against NavierStokesSolver's in a periodic box, between moving z walls and in a channel;
// the energy measures of the slabs (FluidEnergy.hpp) against the whole grid's.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "MpiEnvironment.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/FluidEnergy.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/parallel/HaloExchange.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double kTwoPi = 2 * std::numbers::pi;

// 12 x 10 x 9 cells of h = 0.1: along z 9 cell planes, slabs of 5/4 planes on 2 processes and 3/3/3 on 3; between
// walls 8 planes of u_z unknowns, 5/3 and 3/3/2.
Grid grid_with(const std::array<Boundary, 3>& bc) { return Grid({12, 10, 9}, {1.2, 1.0, 0.9}, bc); }

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
  FluidParams couette = periodic;  // z walls moving along x in opposite directions
  couette.body_force = {};
  couette.wall_lower[2] = {-0.5, 0.0, 0.0};
  couette.wall_upper[2] = {0.5, 0.0, 0.0};
  FluidParams channel = periodic;  // walls along x and z, flow along y, the extrapolated pressure
  channel.mu = 0.2;
  channel.body_force = {0.0, 1.0, 0.0};
  channel.pressure = PressurePredictor::Extrapolated;
  return {Case{"periodic box", {P, P, P}, periodic}, Case{"moving z walls", {P, P, W}, couette},
          Case{"channel (walls along x and z)", {W, P, W}, channel}};
}

// A smooth initial velocity (periodic on every axis, not divergence-free) with the normal wall velocity on the walls.
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

constexpr int kSteps = 5;
double step_size(int n) { return 0.01 * (1.0 + 0.1 * n); }  // a varying step: AB2 and p̃ with r ≠ 1

FluidState run_serial(NavierStokesSolver& serial, FluidState s, const FaceField& force) {
  FluidState next;
  for (int n = 0; n < kSteps; ++n) {
    serial.step(s, force, step_size(n), next);
    std::swap(s, next);
  }
  return s;
}

// Five steps on the slabs from the whole-grid state `start`, gathered on every process.
FluidState run_slabs(SlabNavierStokesSolver& slab, const FluidState& start, const FaceField& force) {
  FluidState s = slab.scatter(start), next;
  const FaceField f = slab.scatter(force);
  for (int n = 0; n < kSteps; ++n) {
    slab.step(s, f, step_size(n), next);
    std::swap(s, next);
  }
  return slab.gather(s);
}

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

bool bitwise_equal(const FluidState& a, const FluidState& b) {
  bool same = a.p.values() == b.p.values() && a.p_prev.values() == b.p_prev.values();
  for (int d = 0; d < 3; ++d)
    same = same && a.u[d].values() == b.u[d].values() && a.adv[d].values() == b.adv[d].values();
  return same;
}

}  // namespace

// Scatter then gather gives back the array; the ghost planes after an exchange hold the neighbours' planes (wrapped on
// a periodic z) and, beyond a wall, the values the serial kernels construct there.
TEST(HaloExchange, GhostPlanesHoldTheNeighboursPlanesOrTheWallValues) {
  const Communicator comm = Communicator::world();
  for (const std::array<Boundary, 3>& bc : {std::array{P, P, P}, std::array{W, P, W}}) {
    const Grid g = grid_with(bc);
    const SlabDecomposition slabs(g, comm);
    const Vec3 lower{-0.5, 0.25, 0.0}, upper{0.5, -0.75, 0.0};
    const HaloExchange halo(slabs, lower, upper);
    for (int l = 0; l < 4; ++l) {
      const Layout layout = static_cast<Layout>(l);
      const auto s = layout == Layout::Pressure ? g.cell_shape() : g.face_shape(l);
      Array3 global(s[0], s[1], s[2]);
      for (std::size_t q = 0; q < global.size(); ++q) global[q] = std::sin(0.37 * static_cast<double>(q)) + 2.0;
      Array3 local;
      slabs.scatter(global, layout, local);
      EXPECT_EQ(slabs.gather(local, layout).values(), global.values()) << "layout " << l;  // (before the walls' ghosts)
      halo.exchange(local, layout);
      const PlaneRange own = slabs.owned(layout);
      const int off = slabs.offset();
      for (int side = 0; side < 2; ++side) {
        const int ghost = side == 0 ? own.begin - 1 : own.end;  // global plane index of the ghost
        const int inner = side == 0 ? own.begin : own.end - 1;
        const Vec3& wall = side == 0 ? lower : upper;
        for (int j = 0; j < s[1]; ++j)
          for (int i = 0; i < s[0]; ++i) {
            double expected = 0;
            if (g.periodic(2))
              expected = global(i, j, (ghost + s[2]) % s[2]);
            else if (ghost >= 0 && ghost < s[2] && !(layout == Layout::VelocityZ && (ghost == 0 || ghost == g.n(2))))
              expected = global(i, j, ghost);
            else if (layout == Layout::Pressure)
              expected = global(i, j, inner);
            else if (layout == Layout::VelocityZ)
              expected = wall[2];
            else
              expected = 2.0 * wall[l] - global(i, j, inner);
            ASSERT_EQ(local(i, j, ghost - off), expected) << "layout " << l << ", side " << side << ", rank "
                                                          << comm.rank();
          }
      }
    }
  }
}

TEST(ParallelFluidStep, FiveStepsOnSlabsEqualTheSerialStepsAndRepeatBitwise) {
  const Communicator comm = Communicator::world();
  for (const Case& c : cases()) {
    const Grid g = grid_with(c.bc);
    NavierStokesSolver serial(g, c.params, FftPlanning::Estimate);
    const FluidState start = initial_state(serial);
    const FaceField force = body_force(g);
    const FluidState expected = run_serial(serial, start, force);

    SlabNavierStokesSolver slab(g, c.params, comm);
    const FluidState result = run_slabs(slab, start, force);
    EXPECT_EQ(result.step, kSteps);
    EXPECT_EQ(result.time, expected.time);
    const double du = relative_difference(result.u, expected.u);
    const double dadv = relative_difference(result.adv, expected.adv);
    const double dp = max_abs_difference(result.p, expected.p) / max_abs(expected.p);
    EXPECT_LE(du, 1e-12) << c.name;
    EXPECT_LE(dadv, 1e-12) << c.name;
    EXPECT_LE(dp, 1e-12) << c.name;
    EXPECT_GT(max_abs(expected.p), 1e-3) << c.name;  // a pressure that is not trivially zero

    // Incompressible after the projection (12).
    Array3 div;
    divergence(g, result.u, div);
    const double max_div = max_abs(div);
    EXPECT_LE(max_div, 1e-12) << c.name;

    // The same run again with the same solver and with a new one: the same bits.
    const FluidState again = run_slabs(slab, start, force);
    EXPECT_TRUE(bitwise_equal(again, result)) << c.name;
    SlabNavierStokesSolver fresh(g, c.params, comm);
    EXPECT_TRUE(bitwise_equal(run_slabs(fresh, start, force), result)) << c.name;

    if (comm.rank() == 0)
      std::printf("%d processes, %s: max relative difference to the serial step u %.2e, p %.2e, (u.grad u) %.2e; "
                  "max |D u| %.2e\n",
                  comm.size(), c.name.c_str(), du, dp, dadv, max_div);
  }
}

// The energy measures of a slab state, each process's plane sums added over the processes, are the whole grid's bit for
// bit, with a constant viscosity and with χ reaching the walls; after five steps on the slabs they agree with the
// serial steps' to round-off.
TEST(ParallelFluidStep, EnergyMeasuresOfTheSlabsAddUpToTheWholeGrids) {
  const Communicator comm = Communicator::world();
  const auto slab_energy = [&](const SlabNavierStokesSolver& slab, const FluidState& local, const Array3* chi) {
    const SlabDecomposition& slabs = slab.decomposition();
    const PlaneRange cells = slabs.cells();
    const auto mine =
        fluid_energy_planes(slab.grid(), slab.params(), local.u, chi, cells.begin, cells.end, slabs.offset());
    return fluid_energy_total(slab.grid(), slab.params(), comm.sum(mine));
  };
  const auto parts = [](const FluidEnergy& e) { return std::array{e.kinetic, e.dissipation, e.walls, e.body}; };
  for (const Case& c : cases()) {
    const Grid g = grid_with(c.bc);
    NavierStokesSolver serial(g, c.params, FftPlanning::Estimate);
    const FluidState start = initial_state(serial);
    SlabNavierStokesSolver slab(g, c.params, comm);
    const FluidState local = slab.scatter(start);
    Array3 chi(g.n(0), g.n(1), g.n(2));
    for (int k = 0; k < g.n(2); ++k)
      for (int j = 0; j < g.n(1); ++j)
        for (int i = 0; i < g.n(0); ++i) chi(i, j, k) = std::max(0.0, std::sin(0.7 * i + 0.4 * j) + std::cos(0.9 * k));
    Array3 chi_local;
    slab.decomposition().scatter(chi, Layout::Pressure, chi_local);
    HaloExchange(slab.decomposition(), {}, {}).exchange(chi_local, Layout::Pressure);
    for (const bool variable : {false, true}) {
      const auto whole = parts(fluid_energy(g, c.params, start.u, variable ? &chi : nullptr));
      const auto sum = parts(slab_energy(slab, local, variable ? &chi_local : nullptr));
      EXPECT_EQ(sum, whole) << c.name << (variable ? ", variable viscosity" : "");
      EXPECT_GT(whole[1], 0) << c.name;
    }
    const FluidEnergy expected = fluid_energy(g, c.params, run_serial(serial, start, body_force(g)).u, nullptr);
    FluidState s = local, next;
    const FaceField f = slab.scatter(body_force(g));
    for (int n = 0; n < kSteps; ++n) {
      slab.step(s, f, step_size(n), next);
      std::swap(s, next);
    }
    const auto after = parts(slab_energy(slab, s, nullptr)), serial_after = parts(expected);
    for (int q = 0; q < 4; ++q)
      EXPECT_NEAR(after[q], serial_after[q], 1e-12 * std::abs(serial_after[1]) + 1e-12 * std::abs(serial_after[q]))
          << c.name << ", measure " << q;
  }
}

// 3 processes for 4 cells between z walls: blocks of 2 leave the last process no cell; 2 processes for 3 cells
// leave it one, too few for a plane of u_z. One process is always accepted.
TEST(ParallelFluidStep, RefusesACutThatLeavesAProcessWithoutPlanes) {
  const Communicator comm = Communicator::world();
  const int p = comm.size();
  const int nz = p == 3 ? 4 : 3;
  const Grid g({4, 3, nz}, {1.0, 0.75, 0.25 * nz}, {P, P, W});
  if (p == 1) {
    EXPECT_NO_THROW({ const SlabDecomposition one(g, comm); });
    return;
  }
  try {
    SlabDecomposition refused(g, comm);
    ADD_FAILURE() << "a decomposition of " << nz << " planes over " << p << " processes was made";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("every process needs at least 2"), std::string::npos) << e.what();
  }
}
