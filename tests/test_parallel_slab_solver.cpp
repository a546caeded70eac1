// Tests of the distributed fast-transform solver and its communicator, run by ctest through mpiexec with 1, 2 and 3
// processes (tests ParallelSlabSolver.np1/np2/np3): the slabs gathered from every process equal the serial
// FftHelmholtzSolver's solution, the residual of the 7-point operator is small, repeated solves are bitwise identical.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "MpiEnvironment.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/SlabFftHelmholtzSolver.hpp"
#include "immerse/parallel/Communicator.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

std::array<int, 3> layout_shape(const Grid& g, Layout layout) {
  return layout == Layout::Pressure ? g.cell_shape() : g.face_shape(static_cast<int>(layout));
}

// A random field (the same on every process: same seed) whose prescribed wall faces are zero.
Array3 random_unknowns(const Grid& g, Layout layout, unsigned seed) {
  const auto s = layout_shape(g, layout);
  Array3 x(s[0], s[1], s[2]);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  for (double& v : x.values()) v = U(rng);
  const int d = static_cast<int>(layout);
  if (layout != Layout::Pressure && !g.periodic(d))
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const int q = d == 0 ? i : (d == 1 ? j : k);
          if (q == 0 || q == g.n(d)) x(i, j, k) = 0;
        }
  return x;
}

// This process's slab of a global array of the solver's layout.
Array3 slab_of(const SlabFftHelmholtzSolver& solver, const Array3& global) {
  const auto s = solver.local_shape();
  Array3 local(s[0], s[1], s[2]);
  for (int k = 0; k < s[2]; ++k)
    for (int j = 0; j < s[1]; ++j)
      for (int i = 0; i < s[0]; ++i) local(i, j, k) = global(i, j, k + solver.first_array_plane());
  return local;
}

// The slabs of every process put back into a copy of `outside` (which supplies the planes no process owns).
Array3 gather(const SlabFftHelmholtzSolver& solver, const Array3& local, const Array3& outside) {
  const std::vector<double> all = solver.communicator().all_gather(local.values());
  Array3 global = outside;
  const std::size_t plane = static_cast<std::size_t>(global.nx()) * global.ny();
  EXPECT_EQ(all.size(), plane * solver.count()[2]);
  std::copy(all.begin(), all.end(), global.values().begin() + static_cast<std::ptrdiff_t>(plane * solver.first()[2]));
  return global;
}

double max_abs(const Array3& a) {
  double m = 0;
  for (double v : a.values()) m = std::max(m, std::abs(v));
  return m;
}

std::string name(Layout layout, const std::array<Boundary, 3>& bc) {
  static const char* layouts[4] = {"u", "v", "w", "p"};
  std::string s = std::string("layout ") + layouts[static_cast<int>(layout)] + ", boundaries ";
  for (Boundary b : bc) s += b == P ? 'P' : 'W';
  return s;
}

}  // namespace

TEST(Communicator, SumAddsInRankOrderAndGivesTheSameBitsOnEveryRank) {
  const Communicator comm = Communicator::world();
  const int p = comm.size(), r = comm.rank();
  ASSERT_GE(p, 1);
  ASSERT_LT(r, p);
  // Values whose sum depends on the order of the additions: 1e16 + 1 + 1 is 1e16 in rank order, not 1e16 + 2.
  const auto value = [](int rank) { return rank == 0 ? 1e16 : 1.0 + 0.1 * rank; };
  double expected = 0;
  for (int q = 0; q < p; ++q) expected += value(q);
  const double total = comm.sum(value(r));
  EXPECT_EQ(total, expected);
  const std::vector<double> every = comm.all_gather(std::span<const double>(&total, 1));
  ASSERT_EQ(every.size(), static_cast<std::size_t>(p));
  for (double t : every) EXPECT_EQ(t, total);
  const std::vector<double> mine = {value(r), -2.0 * r, 0.5};
  const std::vector<double> sums = comm.sum(mine);
  ASSERT_EQ(sums.size(), 3u);
  EXPECT_EQ(sums[0], expected);
  EXPECT_EQ(sums[1], -1.0 * p * (p - 1));
  EXPECT_EQ(sums[2], 0.5 * p);
}

TEST(Communicator, AllGatherConcatenatesArraysOfDifferentLengthsInRankOrder) {
  const Communicator comm = Communicator::world();
  const int p = comm.size(), r = comm.rank();
  const std::vector<double> mine(static_cast<std::size_t>(r + 1), static_cast<double>(r));  // rank r: r + 1 values r
  const std::vector<double> all = comm.all_gather(mine);
  std::vector<double> expected;
  for (int q = 0; q < p; ++q) expected.insert(expected.end(), static_cast<std::size_t>(q + 1), static_cast<double>(q));
  EXPECT_EQ(all, expected);
  comm.barrier();
}

// 12 x 10 x 11 cells: along z 11 planes of cell unknowns (slabs of 6/5 planes on 2 processes, 4/4/3 on 3) and 10 of
// face-normal ones between walls (5/5, 4/4/2). Periodic, walled and both mixed boxes (walls along z, walls along x
// and y), every layout, Helmholtz and Poisson: every transform kind on every axis.
TEST(SlabFftHelmholtzSolver, GatheredSolutionEqualsTheSerialSolverForEveryLayoutAndBoundaryKind) {
  const Communicator comm = Communicator::world();
  double worst_difference[2] = {0, 0}, worst_residual[2] = {0, 0};
  for (const std::array<Boundary, 3>& bc : {std::array{P, P, P}, std::array{W, W, W}, std::array{P, P, W},
                                            std::array{W, W, P}}) {
    const Grid g({12, 10, 11}, {1.2, 1.0, 1.1}, bc);
    for (int l = 0; l < 4; ++l) {
      const Layout layout = static_cast<Layout>(l);
      SlabFftHelmholtzSolver slab(g, layout, comm);
      FftHelmholtzSolver serial(g, layout, FftPlanning::Estimate);
      // The slabs tile the planes of unknowns along z in rank order.
      const std::vector<double> n = comm.all_gather(std::vector<double>{double(slab.local_planes())});
      const std::vector<double> z0 = comm.all_gather(std::vector<double>{double(slab.first_plane())});
      EXPECT_EQ(z0.front(), 0.0);
      for (std::size_t q = 1; q < n.size(); ++q) EXPECT_EQ(z0[q], z0[q - 1] + n[q - 1]) << name(layout, bc);
      EXPECT_EQ(z0.back() + n.back(), slab.count()[2]) << name(layout, bc);
      EXPECT_EQ(slab.count(), serial.count());
      EXPECT_EQ(slab.first(), serial.first());
      const Array3 x = random_unknowns(g, layout, 17u + static_cast<unsigned>(l));
      for (int op = 0; op < 2; ++op) {
        const double alpha = op == 0 ? 1.0 : 0.0, beta = op == 0 ? -0.3 : 1.0;  // Helmholtz, Poisson
        Array3 b;
        apply_operator(g, layout, x, alpha, beta, b);  // in the operator's range: compatible for Poisson
        Array3 expected = b;
        serial.solve(expected, alpha, beta);
        Array3 local = slab_of(slab, b);
        slab.solve(local, alpha, beta);
        const Array3 solution = gather(slab, local, b);
        double difference = 0;
        for (std::size_t q = 0; q < solution.size(); ++q)
          difference = std::max(difference, std::abs(solution[q] - expected[q]));
        difference /= max_abs(expected);
        const double residual = relative_residual(g, layout, solution, b, alpha, beta);
        EXPECT_LE(difference, 1e-12) << name(layout, bc) << (op == 0 ? ", Helmholtz" : ", Poisson");
        EXPECT_LE(residual, 1e-11) << name(layout, bc) << (op == 0 ? ", Helmholtz" : ", Poisson");
        worst_difference[op] = std::max(worst_difference[op], difference);
        worst_residual[op] = std::max(worst_residual[op], residual);
      }
    }
  }
  if (comm.rank() == 0)
    std::printf("%d processes: max relative difference to the serial solver %.2e (Helmholtz), %.2e (Poisson); "
                "max relative residual %.2e (Helmholtz), %.2e (Poisson)\n",
                comm.size(), worst_difference[0], worst_difference[1], worst_residual[0], worst_residual[1]);
}

TEST(SlabFftHelmholtzSolver, RepeatedSolvesAndANewSolverGiveBitwiseIdenticalResults) {
  const Communicator comm = Communicator::world();
  const Grid g({12, 10, 11}, {1.2, 1.0, 1.1}, {W, P, W});
  for (int l = 0; l < 4; ++l) {
    const Layout layout = static_cast<Layout>(l);
    const Array3 x = random_unknowns(g, layout, 5u + static_cast<unsigned>(l));
    Array3 b;
    apply_operator(g, layout, x, 1.0, -0.3, b);
    SlabFftHelmholtzSolver slab(g, layout, comm);
    const Array3 rhs = slab_of(slab, b);
    Array3 first = rhs, second = rhs, third = rhs;
    slab.solve(first, 1.0, -0.3);
    slab.solve(second, 0.0, 1.0);  // another symbol in between
    second = rhs;
    slab.solve(second, 1.0, -0.3);
    SlabFftHelmholtzSolver fresh(g, layout, comm);
    fresh.solve(third, 1.0, -0.3);
    EXPECT_NE(first.values(), rhs.values()) << "layout " << l;
    EXPECT_EQ(first.values(), second.values()) << "layout " << l;
    EXPECT_EQ(first.values(), third.values()) << "layout " << l;
  }
}

// P ≥ 2 cells between walls along z: P − 1 planes of w (refused), P planes of pressure (one per process, solved).
// A grid has at least 2 cells per axis, so with one process (2 cells) w has 1 plane and is accepted: the refusal
// is checked by the runs with 2 and 3 processes.
TEST(SlabFftHelmholtzSolver, RefusesMoreProcessesThanPlanesAlongZ) {
  const Communicator comm = Communicator::world();
  const int p = comm.size(), nz = std::max(p, 2);
  const Grid g({4, 3, nz}, {1.0, 0.75, 0.25 * nz}, {P, W, W});
  if (p > nz - 1) {
    try {
      SlabFftHelmholtzSolver refused(g, Layout::VelocityZ, comm);
      ADD_FAILURE() << "a solver with " << p << " processes for " << nz - 1 << " planes was made";
    } catch (const std::invalid_argument& e) {
      const std::string expected = std::to_string(p) + " processes for " + std::to_string(nz - 1) + " planes";
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("at most one process per plane"), std::string::npos) << e.what();
    }
  } else {
    SlabFftHelmholtzSolver accepted(g, Layout::VelocityZ, comm);
    EXPECT_EQ(accepted.local_planes(), nz - 1);
  }
  SlabFftHelmholtzSolver slab(g, Layout::Pressure, comm);
  EXPECT_EQ(slab.local_planes(), nz / p);
  EXPECT_EQ(slab.first_plane(), comm.rank() * (nz / p));
  const Array3 x = random_unknowns(g, Layout::Pressure, 3u);
  Array3 b;
  apply_operator(g, Layout::Pressure, x, 1.0, -0.3, b);
  Array3 local = slab_of(slab, b);
  slab.solve(local, 1.0, -0.3);
  const Array3 solution = gather(slab, local, b);
  double difference = 0;
  for (std::size_t q = 0; q < solution.size(); ++q) difference = std::max(difference, std::abs(solution[q] - x[q]));
  EXPECT_LE(difference, 1e-12 * max_abs(x));
}

// A given block B of planes per process (the fluid's cell block): process r owns the planes [r B, (r + 1) B) of
// unknowns, here u_z between z walls with 10 planes and B = ⌈11 / P⌉, and solves on them inside a larger array.
// Blocks that do not cover the planes are refused.
TEST(SlabFftHelmholtzSolver, AGivenBlockOfPlanesGivesThatDistributionAndTheSerialSolution) {
  const Communicator comm = Communicator::world();
  const int p = comm.size(), r = comm.rank();
  const Grid g({12, 10, 11}, {1.2, 1.0, 1.1}, {P, W, W});
  const int block = (11 + p - 1) / p;
  SlabFftHelmholtzSolver slab(g, Layout::VelocityZ, comm, block);
  EXPECT_EQ(slab.first_plane(), std::min(r * block, 10));
  EXPECT_EQ(slab.local_planes(), std::max(std::min((r + 1) * block, 10) - r * block, 0));
  FftHelmholtzSolver serial(g, Layout::VelocityZ, FftPlanning::Estimate);
  const Array3 x = random_unknowns(g, Layout::VelocityZ, 11u);
  Array3 b;
  apply_operator(g, Layout::VelocityZ, x, 1.0, -0.3, b);
  Array3 expected = b;
  serial.solve(expected, 1.0, -0.3);
  // The slab with a plane of 7s below and above it, which the solve leaves as they are.
  const Array3 inner = slab_of(slab, b);
  Array3 padded(inner.nx(), inner.ny(), inner.nz() + 2, 7.0);
  for (int k = 0; k < inner.nz(); ++k)
    for (int j = 0; j < inner.ny(); ++j)
      for (int i = 0; i < inner.nx(); ++i) padded(i, j, k + 1) = inner(i, j, k);
  slab.solve(padded, 1, 1.0, -0.3);
  Array3 local = inner;
  for (int k = 0; k < inner.nz(); ++k)
    for (int j = 0; j < inner.ny(); ++j)
      for (int i = 0; i < inner.nx(); ++i) local(i, j, k) = padded(i, j, k + 1);
  for (int k : {0, inner.nz() + 1})
    for (int j = 0; j < inner.ny(); ++j)
      for (int i = 0; i < inner.nx(); ++i) EXPECT_EQ(padded(i, j, k), 7.0);
  const Array3 solution = gather(slab, local, b);
  double difference = 0;
  for (std::size_t q = 0; q < solution.size(); ++q)
    difference = std::max(difference, std::abs(solution[q] - expected[q]));
  EXPECT_LE(difference, 1e-12 * max_abs(expected));
  for (int bad : {0, 1}) {  // no block; 1 plane each does not cover 10 planes with at most 3 processes
    try {
      SlabFftHelmholtzSolver refused(g, Layout::VelocityZ, comm, bad);
      ADD_FAILURE() << "a solver with blocks of " << bad << " planes was made";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad == 0 ? "at least 1" : "do not cover the 10 planes"), std::string::npos)
          << e.what();
    }
  }
}
