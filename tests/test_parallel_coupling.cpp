// Tests of the distributed membranes and coupling, run by ctest through mpiexec with 1, 2 and 3 processes (tests
// ParallelCoupling.np1/np2/np3): membrane ownership and migration (MembraneOwnership), spreading and interpolation on
// the slabs (SlabIBCoupler) against the whole-grid IBCoupler, the adjoint identity, bitwise repetition, and one coupled
// forward Euler step against the serial one.
//
// Grid: 16 x 12 x 15 cells of h = 0.1, periodic along x and y, z either between walls or periodic. Along z, 15 cell
// planes: slabs of 8/7 planes on 2 processes (boundary at z = 0.8) and 5/5/5 on 3 (boundaries at z = 0.5 and 1.0).
// Spheres of 642 nodes (icosahedral, level 2) straddle these boundaries, the periodic x and y boundaries, the
// periodic z boundary (periodic case) and come within the kernel reach of the z walls (wall case).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "MpiEnvironment.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/parallel/MembraneOwnership.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double kTwoPi = 2 * std::numbers::pi;

Grid grid_with(Boundary z) { return Grid({16, 12, 15}, {1.6, 1.2, 1.5}, {P, P, z}); }

struct Sphere {
  Vec3 centre;
  double radius;
};

// Centroid cells along z (h = 0.1): 2, 7, 10, 13 and, periodic only, 14 and 0.
std::vector<Sphere> spheres(const Grid& g) {
  std::vector<Sphere> s{
      {{0.4, 0.3, 0.22}, 0.2},    // reaches within 0.02 of the lower wall
      {{1.0, 0.7, 0.78}, 0.25},   // across z = 0.5 and z = 0.8
      {{1.45, 1.0, 1.02}, 0.25},  // across the periodic x and y boundaries, z = 0.8 and z = 1.0
      {{0.3, 0.9, 1.3}, 0.18},    // reaches within 0.02 of the upper wall
  };
  if (g.periodic(2)) {
    s.push_back({{0.8, 0.2, 1.45}, 0.25});  // across the periodic z boundary: nodes up to z = 1.7
    s.push_back({{1.2, 0.5, 0.03}, 0.2});   // nodes down to z = −0.17
  }
  return s;
}

const Mesh& unit_sphere() {
  static const Mesh mesh = icosahedral_sphere(2);
  return mesh;
}

std::vector<Vec3> place(const Sphere& s, const Vec3& stretch = {1, 1, 1}) {
  std::vector<Vec3> X;
  for (const Vec3& x : unit_sphere().nodes)
    X.push_back(s.centre + Vec3{stretch[0] * x[0], stretch[1] * x[1], stretch[2] * x[2]} * s.radius);
  return X;
}

std::vector<Vec3> concatenate(const std::vector<std::vector<Vec3>>& membranes) {
  std::vector<Vec3> X;
  for (const auto& m : membranes) X.insert(X.end(), m.begin(), m.end());
  return X;
}

// A smooth nodal force (N) and a smooth velocity field.
Vec3 smooth_force(const Grid& g, const Vec3& x) {
  const double a = kTwoPi * x[0] / g.length(0), b = kTwoPi * x[1] / g.length(1), c = kTwoPi * x[2] / g.length(2);
  return Vec3{std::sin(a + 0.3) + 0.5 * std::cos(c), std::cos(b) * std::sin(c) + 0.2, 0.7 * std::cos(a + b) + 0.1} *
         1e-3;
}

FaceField smooth_velocity(const Grid& g) {
  FaceField u(g);
  sample_velocity(
      g,
      [&](const Vec3& x) {
        const double a = kTwoPi * x[0] / g.length(0), b = kTwoPi * x[1] / g.length(1),
                     c = kTwoPi * x[2] / g.length(2);
        return Vec3{0.6 * std::sin(b) * std::cos(c) + 0.2 * std::cos(a), 0.5 * std::sin(c) * std::cos(a) + 0.1,
                    0.4 * std::sin(a) * std::cos(b + c)};
      },
      u);
  return u;
}

std::vector<Vec3> forces_at(const Grid& g, std::span<const Vec3> X) {
  std::vector<Vec3> F;
  for (const Vec3& x : X) F.push_back(smooth_force(g, x));
  return F;
}

double max_abs(const FaceField& f) {
  double m = 0;
  for (int d = 0; d < 3; ++d)
    for (double v : f[d].values()) m = std::max(m, std::abs(v));
  return m;
}

double relative_difference(const FaceField& a, const FaceField& b) {
  double diff = 0;
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(a[d].shape(), b[d].shape());
    for (std::size_t q = 0; q < std::min(a[d].size(), b[d].size()); ++q)
      diff = std::max(diff, std::abs(a[d][q] - b[d][q]));
  }
  return diff / max_abs(b);
}

double relative_difference(std::span<const Vec3> a, std::span<const Vec3> b) {
  EXPECT_EQ(a.size(), b.size());
  double diff = 0, scale = 0;
  for (std::size_t l = 0; l < std::min(a.size(), b.size()); ++l)
    for (int c = 0; c < 3; ++c) {
      diff = std::max(diff, std::abs(a[l][c] - b[l][c]));
      scale = std::max(scale, std::abs(b[l][c]));
    }
  return diff / scale;
}

FaceField gather(const SlabDecomposition& slabs, const FaceField& local) {
  FaceField global;
  for (int d = 0; d < 3; ++d) global[d] = slabs.gather(local[d], velocity_layout(d));
  return global;
}

FaceField scatter(const SlabDecomposition& slabs, const FaceField& global) {
  FaceField local;
  for (int d = 0; d < 3; ++d) slabs.scatter(global[d], velocity_layout(d), local[d]);
  return local;
}

bool bitwise_equal(const FaceField& a, const FaceField& b) {
  for (int d = 0; d < 3; ++d)
    if (a[d].values() != b[d].values()) return false;
  return true;
}

bool bitwise_equal(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t l = 0; l < a.size(); ++l)
    for (int c = 0; c < 3; ++c)
      if (a[l][c] != b[l][c]) return false;
  return true;
}

/// The rank that must own a membrane with centroid z coordinate cz, computed here from the rule.
int expected_owner(const Grid& g, int processes, double cz) {
  double z = cz - g.origin()[2];
  if (g.periodic(2)) z -= g.length(2) * std::floor(z / g.length(2));
  const int cell = std::clamp(static_cast<int>(std::floor(z / g.h())), 0, g.n(2) - 1);
  const int block = (g.n(2) + processes - 1) / processes;
  return cell / block;
}

/// The h³-weighted inner product over every stored point, from the held planes of the slabs.
double slab_inner_product(const SlabDecomposition& slabs, const FaceField& f, const FaceField& u) {
  double sum = 0;
  for (int d = 0; d < 3; ++d) {
    const PlaneRange held = slabs.held(velocity_layout(d));
    const std::size_t begin = f[d].index(0, 0, held.begin - slabs.offset());
    const std::size_t end = f[d].index(0, 0, held.end - slabs.offset());
    for (std::size_t q = begin; q < end; ++q) sum += f[d][q] * u[d][q];
  }
  return slabs.communicator().sum(sum) * slabs.grid().cell_volume();
}

double node_inner_product(const Communicator& comm, std::span<const Vec3> F, std::span<const Vec3> U) {
  double sum = 0;
  for (std::size_t l = 0; l < F.size(); ++l) sum += F[l][0] * U[l][0] + F[l][1] * U[l][1] + F[l][2] * U[l][2];
  return comm.sum(sum);
}

struct Case {
  std::string name;
  Boundary z;
  DeltaKernel kernel;
};

std::vector<Case> cases() {
  return {{"z walls, roma3", W, RomaPeskin3{}}, {"z walls, peskin4", W, Peskin4{}},
          {"periodic, roma3", P, RomaPeskin3{}}, {"periodic, peskin4", P, Peskin4{}}};
}

}  // namespace

// Every plane of every layout has exactly one holder, the process whose held() planes contain it.
TEST(ParallelCoupling, HolderOfEveryPlane) {
  const Communicator comm = Communicator::world();
  for (Boundary z : {W, P}) {
    const Grid g = grid_with(z);
    const SlabDecomposition slabs(g, comm);
    for (int l = 0; l < 4; ++l) {
      const Layout layout = static_cast<Layout>(l);
      const int planes = layout == Layout::Pressure ? g.n(2) : g.face_shape(l)[2];
      const PlaneRange held = slabs.held(layout);
      int mine = 0;
      for (int p = 0; p < planes; ++p) {
        const bool held_here = p >= held.begin && p < held.end;
        EXPECT_EQ(slabs.holder(layout, p) == comm.rank(), held_here) << "layout " << l << ", plane " << p;
        mine += held_here;
      }
      EXPECT_EQ(comm.sum(mine), planes) << "layout " << l;
    }
  }
}

// (a), (b), (c), (e): spreading and interpolation of the owned membranes against IBCoupler over all membranes; the
// adjoint identity; the same bits again from the same coupler and from a new one.
TEST(ParallelCoupling, SpreadingAndInterpolationEqualTheSerialCouplerAndRepeatBitwise) {
  const Communicator comm = Communicator::world();
  for (const Case& c : cases()) {
    const Grid g = grid_with(c.z);
    const SlabDecomposition slabs(g, comm);
    std::vector<std::vector<Vec3>> membranes;
    for (const Sphere& s : spheres(g)) membranes.push_back(place(s));
    const MembraneOwnership ownership(slabs, membranes, membranes);
    for (std::size_t m = 0; m < membranes.size(); ++m) {
      const bool here = std::any_of(ownership.owned().begin(), ownership.owned().end(),
                                    [&](const OwnedMembrane& o) { return o.id == static_cast<int>(m); });
      const int owner = expected_owner(g, comm.size(), MembraneOwnership::centroid(membranes[m])[2]);
      EXPECT_EQ(here, owner == comm.rank()) << c.name << ", membrane " << m;
      EXPECT_EQ(comm.sum(here ? 1.0 : 0.0), 1.0) << c.name << ", membrane " << m;
    }

    // Serial.
    const std::vector<Vec3> X = concatenate(membranes), F = forces_at(g, X);
    IBCoupler serial(g, c.kernel);
    FaceField f_serial(g);
    serial.spread_force(X, F, f_serial);
    const FaceField u = smooth_velocity(g);
    std::vector<Vec3> U_serial(X.size());
    serial.interpolate_velocity(u, X, U_serial);

    // Distributed.
    const std::vector<Vec3> Xo = ownership.owned_positions(), Fo = forces_at(g, Xo);
    SlabIBCoupler coupler(slabs, c.kernel);
    FaceField f;
    coupler.spread_force(Xo, Fo, f);
    const double df = relative_difference(gather(slabs, f), f_serial);
    EXPECT_LE(df, 1e-12) << c.name;
    const FaceField u_slab = scatter(slabs, u);
    std::vector<Vec3> Uo(Xo.size());
    coupler.interpolate_velocity(u_slab, Xo, Uo);
    const std::vector<Vec3> U = ownership.gather(Uo);
    const double du = relative_difference(U, U_serial);
    EXPECT_LE(du, 1e-12) << c.name;

    // The adjoint identity ⟨S F, u⟩ h³ = ⟨F, J u⟩ on the distributed operators.
    const double sfu = slab_inner_product(slabs, f, u_slab), fju = node_inner_product(comm, Fo, Uo);
    const double adjoint = std::abs(sfu - fju) / std::max(std::abs(sfu), std::abs(fju));
    EXPECT_LE(adjoint, 1e-12) << c.name;
    EXPECT_GT(std::abs(sfu), 1e-6) << c.name;  // not trivially zero

    // Repeated: the same bits, from this coupler and from a new one.
    FaceField f_again;
    coupler.spread_force(Xo, Fo, f_again);
    EXPECT_TRUE(bitwise_equal(f_again, f)) << c.name;
    SlabIBCoupler fresh(slabs, c.kernel);
    FaceField f_fresh;
    fresh.spread_force(Xo, Fo, f_fresh);
    EXPECT_TRUE(bitwise_equal(f_fresh, f)) << c.name;
    std::vector<Vec3> U_again(Xo.size());
    fresh.interpolate_velocity(u_slab, Xo, U_again);
    EXPECT_TRUE(bitwise_equal(U_again, Uo)) << c.name;

    if (comm.rank() == 0)
      std::printf("%d processes, %s: max relative difference to IBCoupler: spreading %.2e, interpolation %.2e; "
                  "adjoint identity %.2e\n",
                  comm.size(), c.name.c_str(), df, du, adjoint);
  }
}

// (d): membranes moved rigidly across a slab boundary (and, periodic, across the periodic z boundary) migrate to the
// owner of their new centroid; the gathered positions are the moved ones bitwise, per-node values sent after them
// (MembraneOwnership::follow, as an integrator's history) arrive with them, and spreading after the migration still
// equals IBCoupler's.
TEST(ParallelCoupling, MigrationMovesMembranesToTheirNewOwners) {
  const Communicator comm = Communicator::world();
  for (Boundary z : {W, P}) {
    const Grid g = grid_with(z);
    const SlabDecomposition slabs(g, comm);
    std::vector<std::vector<Vec3>> membranes, reference;
    for (const Sphere& s : spheres(g)) {
      membranes.push_back(place(s, {1.1, 1.0, 0.9}));
      reference.push_back(place(s));
    }
    MembraneOwnership ownership(slabs, membranes, reference);
    // Membrane 1 from z = 0.78 to 1.08 (cell 7 to 10: process 0 to 1 of 2, 1 to 2 of 3); periodic: membrane 4 from
    // z = 1.45 to 1.65 ≡ 0.15 (cell 14 to 1: the last process to the first).
    std::vector<std::vector<Vec3>> moved = membranes;
    std::vector<std::pair<int, Vec3>> moves{{1, {0.05, -0.02, 0.3}}};
    if (g.periodic(2)) moves.push_back({4, {0.0, 0.03, 0.2}});
    int expected_moves = 0;
    for (const auto& [m, shift] : moves) {
      const double before = MembraneOwnership::centroid(moved[m])[2];
      for (Vec3& x : moved[m]) x += shift;
      const double after = MembraneOwnership::centroid(moved[m])[2];
      expected_moves += expected_owner(g, comm.size(), before) != expected_owner(g, comm.size(), after);
    }
    for (OwnedMembrane& o : ownership.owned()) o.positions = moved[o.id];
    // Three arrays of per-node values (membrane, node, component and array encoded) over the owned membranes.
    const auto value = [](int m, std::size_t i, int k, std::size_t a) {
      return 1e4 * m + 4.0 * static_cast<double>(i) + k + 0.25 * static_cast<double>(a);
    };
    constexpr std::size_t arrays = 3;
    std::vector<double> before;
    for (std::size_t a = 0; a < arrays; ++a)
      for (const OwnedMembrane& o : ownership.owned())
        for (std::size_t i = 0; i < o.positions.size(); ++i)
          for (int k = 0; k < 3; ++k) before.push_back(value(o.id, i, k, a));
    const int count = ownership.migrate();
    EXPECT_EQ(count, expected_moves);
    // The values moved with their membranes: the same arrays over the membranes owned now, in their order.
    const std::vector<double> now = ownership.follow(before, arrays);
    ASSERT_EQ(now.size(), arrays * 3 * ownership.num_owned_nodes());
    std::size_t at = 0;
    for (std::size_t a = 0; a < arrays; ++a)
      for (const OwnedMembrane& o : ownership.owned())
        for (std::size_t i = 0; i < o.positions.size(); ++i)
          for (int k = 0; k < 3; ++k) ASSERT_EQ(now[at++], value(o.id, i, k, a)) << "membrane " << o.id;
    if (comm.size() > 1) {
      EXPECT_EQ(count, static_cast<int>(moves.size()));
    }
    for (std::size_t m = 0; m < moved.size(); ++m) {
      const auto it = std::find_if(ownership.owned().begin(), ownership.owned().end(),
                                   [&](const OwnedMembrane& o) { return o.id == static_cast<int>(m); });
      const bool here = it != ownership.owned().end();
      EXPECT_EQ(here, expected_owner(g, comm.size(), MembraneOwnership::centroid(moved[m])[2]) == comm.rank())
          << "membrane " << m;
      if (here) {
        EXPECT_TRUE(bitwise_equal(it->reference, reference[m])) << "membrane " << m;
      }
    }
    const std::vector<std::vector<Vec3>> gathered = ownership.gather_positions();
    ASSERT_EQ(gathered.size(), moved.size());
    for (std::size_t m = 0; m < moved.size(); ++m) EXPECT_TRUE(bitwise_equal(gathered[m], moved[m])) << m;
    EXPECT_TRUE(std::is_sorted(ownership.owned().begin(), ownership.owned().end(),
                               [](const OwnedMembrane& a, const OwnedMembrane& b) { return a.id < b.id; }));

    // Spreading after the migration.
    const std::vector<Vec3> X = concatenate(moved);
    IBCoupler serial(g);
    FaceField f_serial(g);
    serial.spread_force(X, forces_at(g, X), f_serial);
    const std::vector<Vec3> Xo = ownership.owned_positions();
    SlabIBCoupler coupler(slabs);
    FaceField f;
    coupler.spread_force(Xo, forces_at(g, Xo), f);
    const double df = relative_difference(gather(slabs, f), f_serial);
    EXPECT_LE(df, 1e-12);
    if (comm.rank() == 0)
      std::printf("%d processes, %s: %d membranes migrated; spreading after migration %.2e\n", comm.size(),
                  g.periodic(2) ? "periodic" : "z walls", count, df);
  }
}

// (f): one explicit coupled step, twice: membrane forces (ElasticMembrane) -> spreading -> fluid step ->
// interpolation of u^{n+1} -> X += Δt U, then migration; distributed against serial.
TEST(ParallelCoupling, CoupledForwardEulerStepsEqualTheSerialSteps) {
  const Communicator comm = Communicator::world();
  for (Boundary z : {W, P}) {
    const Grid g = grid_with(z);
    FluidParams params;
    params.rho = 1.0;
    params.mu = 0.05;
    if (z == W) {
      params.wall_lower[2] = {-0.2, 0.0, 0.0};
      params.wall_upper[2] = {0.2, 0.0, 0.0};
    }
    NavierStokesSolver fluid(g, params, FftPlanning::Estimate);
    FluidState state = fluid.initial_state();
    state.u = smooth_velocity(g);
    fluid.apply_wall_values(state.u);

    std::vector<std::vector<Vec3>> start, reference;
    std::vector<ElasticMembrane> elastic;
    std::vector<Sphere> placed = spheres(g);
    placed[1].centre[2] = 0.801;  // just above z = 0.8, its centroid moves down by 0.0025 in the two steps
    placed[2].centre[2] = 0.999;  // just below z = 1.0, moves up by 0.0025
    for (const Sphere& s : placed) {
      start.push_back(place(s, {1.15, 0.95, 0.9}));
      reference.push_back(place(s));
      Mesh mesh = unit_sphere();
      mesh.nodes = reference.back();
      elastic.emplace_back(mesh, reference.back(), NeoHookean(0.05), Bending{}, ForceMethod::Energy);
    }
    constexpr int kSteps = 2;
    constexpr double dt = 0.02;

    // Serial.
    std::vector<std::vector<Vec3>> X = start;
    IBCoupler serial(g);
    FaceField f(g);
    FluidState next;
    for (int n = 0; n < kSteps; ++n) {
      std::vector<Vec3> F;
      for (std::size_t m = 0; m < X.size(); ++m) {
        std::vector<Vec3> Fm;
        elastic[m].compute_force(X[m], Fm);
        F.insert(F.end(), Fm.begin(), Fm.end());
      }
      const std::vector<Vec3> all = concatenate(X);
      serial.spread_force(all, F, f);
      fluid.step(state, f, dt, next);
      std::swap(state, next);
      std::vector<Vec3> U(all.size());
      serial.interpolate_velocity(state.u, all, U);
      std::size_t at = 0;
      for (auto& m : X)
        for (Vec3& x : m) x += U[at++] * dt;
    }

    // Distributed, twice (the second run must give the same bits).
    FluidState initial = fluid.initial_state();
    initial.u = smooth_velocity(g);
    fluid.apply_wall_values(initial.u);
    SlabNavierStokesSolver slab_fluid(g, params, comm);
    const SlabDecomposition& slabs = slab_fluid.decomposition();
    int migrated = 0;
    const auto run = [&](FluidState& s) {
      s = slab_fluid.scatter(initial);
      FluidState s_next;
      MembraneOwnership ownership(slabs, start, reference);
      SlabIBCoupler coupler(slabs);
      FaceField fs;
      migrated = 0;
      for (int n = 0; n < kSteps; ++n) {
        std::vector<Vec3> F;
        for (const OwnedMembrane& o : ownership.owned()) {
          std::vector<Vec3> Fm;
          elastic[o.id].compute_force(o.positions, Fm);
          F.insert(F.end(), Fm.begin(), Fm.end());
        }
        const std::vector<Vec3> mine = ownership.owned_positions();
        coupler.spread_force(mine, F, fs);
        slab_fluid.step(s, fs, dt, s_next);
        std::swap(s, s_next);
        std::vector<Vec3> U(mine.size()), moved = mine;
        coupler.interpolate_velocity(s.u, mine, U);
        for (std::size_t l = 0; l < moved.size(); ++l) moved[l] += U[l] * dt;
        ownership.set_owned_positions(moved);
        migrated += ownership.migrate();
      }
      return ownership.gather_positions();
    };
    FluidState s, s_again;
    const std::vector<std::vector<Vec3>> result = run(s);
    const std::vector<std::vector<Vec3>> again = run(s_again);
    for (std::size_t m = 0; m < result.size(); ++m) EXPECT_TRUE(bitwise_equal(again[m], result[m])) << m;
    for (int d = 0; d < 3; ++d) EXPECT_EQ(s_again.u[d].values(), s.u[d].values());
    // Membranes 1 and 2 cross z = 0.8 downwards and z = 1.0 upwards: a migration on 2 and on 3 processes.
    if (comm.size() > 1) {
      EXPECT_EQ(migrated, 1);
    }
    std::vector<Vec3> displacement, expected_displacement;
    for (std::size_t m = 0; m < X.size(); ++m)
      for (std::size_t i = 0; i < X[m].size(); ++i) {
        displacement.push_back(result[m][i] - start[m][i]);
        expected_displacement.push_back(X[m][i] - start[m][i]);
      }
    const double dx = relative_difference(displacement, expected_displacement);
    const double du = relative_difference(slab_fluid.gather(s).u, state.u);
    EXPECT_LE(dx, 1e-12);
    EXPECT_LE(du, 1e-12);
    if (comm.rank() == 0)
      std::printf("%d processes, %s: %d coupled forward Euler steps: max relative difference to the serial steps: "
                  "node displacement %.2e, u %.2e (%d migrations)\n",
                  comm.size(), z == W ? "z walls" : "periodic", kSteps, dx, du, migrated);
  }
}

// A single membrane, owned by the first process, reaching into the slab of the second on 3 processes: the
// processes without membranes still hold and receive their planes (and send none).
TEST(ParallelCoupling, ProcessesWithoutMembranes) {
  const Communicator comm = Communicator::world();
  for (Boundary z : {W, P}) {
    const Grid g = grid_with(z);
    const SlabDecomposition slabs(g, comm);
    const std::vector<std::vector<Vec3>> membranes{place({{0.7, 0.6, 0.35}, 0.3})};  // z from 0.05 to 0.65
    const MembraneOwnership ownership(slabs, membranes, membranes);
    EXPECT_EQ(ownership.owned().size(), comm.rank() == 0 ? 1u : 0u);
    const std::vector<Vec3>& X = membranes[0];
    IBCoupler serial(g);
    FaceField f_serial(g);
    serial.spread_force(X, forces_at(g, X), f_serial);
    const FaceField u = smooth_velocity(g);
    std::vector<Vec3> U_serial(X.size());
    serial.interpolate_velocity(u, X, U_serial);

    const std::vector<Vec3> Xo = ownership.owned_positions();
    SlabIBCoupler coupler(slabs);
    FaceField f;
    coupler.spread_force(Xo, forces_at(g, Xo), f);
    EXPECT_LE(relative_difference(gather(slabs, f), f_serial), 1e-12);
    std::vector<Vec3> Uo(Xo.size());
    coupler.interpolate_velocity(scatter(slabs, u), Xo, Uo);
    EXPECT_TRUE(bitwise_equal(ownership.gather(Uo), U_serial));
  }
}

// The ghost width: nodes anywhere in the owned cell planes [z0, z1) need the planes of cell centres
// [z0 − 1, z1 + 1) (roma3) or [z0 − 2, z1 + 2) (peskin4) and the faces of u_z [z0 − 1, z1 + 2) (both), at most 2
// planes beyond the owned ones on each side, clipped to the stored planes between walls.
TEST(ParallelCoupling, GhostWidthOfNodesInsideTheSlab) {
  const Communicator comm = Communicator::world();
  for (Boundary z : {W, P})
    for (const DeltaKernel& kernel : {DeltaKernel(RomaPeskin3{}), DeltaKernel(Peskin4{})}) {
      const Grid g = grid_with(z);
      const SlabDecomposition slabs(g, comm);
      const PlaneRange cells = slabs.cells();
      std::vector<Vec3> X;
      for (double t = cells.begin; t < cells.end; t += 0.125) X.push_back({0.37, 0.51, t * g.h()});
      X.push_back({0.37, 0.51, (cells.end - 1e-9) * g.h()});
      SlabIBCoupler coupler(slabs, kernel);
      FaceField f;
      coupler.spread_force(X, std::vector<Vec3>(X.size()), f);
      const int wc = kernel_width(kernel) == 3 ? 1 : 2;
      for (int d = 0; d < 3; ++d) {
        PlaneRange expected = d < 2 ? PlaneRange{cells.begin - wc, cells.end + wc}
                                    : PlaneRange{cells.begin - 1, cells.end + 2};
        if (z == W) {
          expected.begin = std::max(expected.begin, 0);
          expected.end = std::min(expected.end, g.face_shape(d)[2]);
        }
        const PlaneRange got = coupler.buffer_planes(d);
        EXPECT_EQ(got.begin, expected.begin) << kernel_name(kernel) << ", component " << d;
        EXPECT_EQ(got.end, expected.end) << kernel_name(kernel) << ", component " << d;
        const PlaneRange owned = slabs.owned(velocity_layout(d));
        EXPECT_GE(got.begin, owned.begin - 2);
        EXPECT_LE(got.end, owned.end + 2);
      }
    }
}
