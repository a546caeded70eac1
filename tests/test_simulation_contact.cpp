// Contact forces (ContactForce.hpp): the law (minus the gradient of the energy, zero beyond the range, equal and
// opposite for a pair, normal to a wall), the cell-list search against brute force in a periodic box, and in runs:
// two capsules brought together by a shear flow stay apart, an isolated capsule moves as without contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "immerse/contact/ContactForce.hpp"
#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/io/ConfigSchema.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/walls/WallGeometry.hpp"
#include "PetscEnvironment.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

std::array<double, 3> xyz(const Vec3& v) { return {v.x, v.y, v.z}; }
const std::array<double, 3> kZero{0, 0, 0};

// Three "membranes" of random nodes in a box periodic along x and y, with walls at z = 0 and 6.
struct Cloud {
  Grid grid{{8, 10, 6}, {8.0, 10.0, 6.0}, {P, P, W}};
  std::vector<std::size_t> offsets{0, 50, 90, 150};
  std::vector<Vec3> X;
  explicit Cloud(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(0, 1);
    for (std::size_t i = 0; i < offsets.back(); ++i) X.push_back({8 * U(rng) - 0.5, 10 * U(rng) + 0.3, 6 * U(rng)});
  }
  ContactForce contact(double range, bool walls = true) const {
    return ContactForce(grid, {range, 0.7, walls, {}}, offsets, {2.0, 3.0, 5.0});
  }
};

TEST(ContactForce, IsMinusTheGradientOfTheEnergy) {
  Cloud c(3);
  auto contact = c.contact(1.2);
  std::vector<Vec3> F(c.X.size());
  contact.compute(c.X, F);
  const double step = 1e-6;
  double largest = 0, worst = 0;
  int active = 0;
  for (std::size_t i = 0; i < c.X.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      auto Xp = c.X, Xm = c.X;
      Xp[i][k] += step;
      Xm[i][k] -= step;
      const double fd = -(contact.energy(Xp) - contact.energy(Xm)) / (2 * step);
      largest = std::max(largest, std::abs(F[i][k]));
      worst = std::max(worst, std::abs(fd - F[i][k]));
      active += F[i][k] != 0;
    }
  EXPECT_GT(active, 100);  // most nodes have a neighbour or a wall within range
  EXPECT_LT(worst, 1e-7 * largest) << "largest force " << largest;
}

TEST(ContactForce, ForceAndItsDerivativeVanishAtTheRange) {
  const double d = 0.3;
  EXPECT_EQ(ContactForce::pair_force_shape(d, d), 0.0);
  EXPECT_EQ(ContactForce::pair_force_shape(1.5 * d, d), 0.0);
  EXPECT_EQ(ContactForce::pair_force_shape(0.0, d), 1.0);
  // dF/dr = -2 (1 - r/d) / d -> 0: the one-sided difference just inside d is O(step).
  const double step = 1e-7;
  EXPECT_LT(ContactForce::pair_force_shape(d - step, d) / step, 1e-5);
  // Two nodes of different membranes just beyond d (and far from the walls): exactly zero.
  const Grid g({10, 10, 10}, {1.0, 1.0, 1.0}, {W, W, W});
  ContactForce contact(g, {d, 1.0, true, {}}, {0, 1, 2}, {1.0, 1.0});
  std::vector<Vec3> X{{0.5, 0.5, 0.35}, {0.5, 0.5, 0.35 + d * (1 + 1e-12)}}, F(2);
  contact.compute(X, F);
  EXPECT_EQ(xyz(F[0]), kZero);
  EXPECT_EQ(xyz(F[1]), kZero);
}

TEST(ContactForce, PairForcesAreEqualAndOppositeAcrossAPeriodicEnd) {
  const Grid g({10, 10, 10}, {1.0, 1.0, 1.0}, {P, P, P});
  ContactForce contact(g, {0.2, 1.5, true, {}}, {0, 1, 2}, {2.0, 4.0});
  // 0.06 apart through the periodic end of x, offset along y and z.
  std::vector<Vec3> X{{0.98, 0.5, 0.5}, {0.02, 0.53, 0.49}}, F(2);
  contact.compute(X, F);
  EXPECT_EQ(xyz(F[0] + F[1]), kZero);
  const Vec3 dx{-0.04, -0.03, 0.01};  // X0 - X1 by minimum image
  const double r = norm(dx), magnitude = 1.5 * 3.0 * 0.2 * std::pow(1 - r / 0.2, 2);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(F[0][k], magnitude * dx[k] / r, 1e-14);
  // The total force of a random cloud without walls is zero up to round-off.
  Cloud c(5);
  auto free = c.contact(1.2, false);
  std::vector<Vec3> Fc(c.X.size());
  free.compute(c.X, Fc);
  Vec3 total{};
  double largest = 0;
  for (const auto& f : Fc) total += f, largest = std::max(largest, norm(f));
  EXPECT_GT(largest, 0.1);
  EXPECT_LT(norm(total), 1e-13 * largest * double(Fc.size()));
}

TEST(ContactForce, WallForceIsNormalToTheWallAndPointsInside) {
  const Grid g({10, 10, 10}, {1.0, 1.0, 1.0}, {P, W, P});
  ContactForce contact(g, {0.1, 2.0, true, {}}, {0, 2}, {3.0});
  std::vector<Vec3> X{{0.3, 0.04, 0.7}, {0.6, 0.97, 0.2}}, F(2);
  contact.compute(X, F);
  EXPECT_EQ(F[0].x, 0.0);
  EXPECT_EQ(F[0].z, 0.0);
  EXPECT_DOUBLE_EQ(F[0].y, 2.0 * 3.0 * 0.1 * 0.6 * 0.6);
  EXPECT_EQ(F[1].x, 0.0);
  EXPECT_EQ(F[1].z, 0.0);
  EXPECT_DOUBLE_EQ(F[1].y, -2.0 * 3.0 * 0.1 * 0.7 * 0.7);
  ContactForce off(g, {0.1, 2.0, false, {}}, {0, 2}, {3.0});
  off.compute(X, F);
  EXPECT_EQ(xyz(F[0]), kZero);
}

// A tube of radius 1 along z ([[wall]]): nodes within the range of its surface are pushed towards the axis by the law
// of s = R − r, the force minus the energy's gradient; a node near the axis feels nothing.
TEST(ContactForce, CurvedWallPushesNodesAlongItsNormalIntoTheFluid) {
  const Grid g({12, 12, 6}, {3.0, 3.0, 1.5}, {P, P, P});
  ContactSettings settings{0.2, 2.0, true, {}};
  settings.shapes = std::make_shared<const WallGeometry>(
      std::vector<WallShape>{{WallShape::Kind::Tube, {1.5, 1.5, 0.75}, {0, 0, 1}, 1.0, 0, "wall[0]"}}, g);
  ContactForce contact(g, settings, {0, 3}, {3.0});
  const double c = std::sqrt(0.5);
  std::vector<Vec3> X{{1.5 + 0.9 * c, 1.5 + 0.9 * c, 0.3}, {1.5, 1.5 - 1.05, 1.0}, {1.6, 1.5, 0.2}}, F(3);
  contact.compute(X, F);
  const double f0 = 2.0 * 3.0 * 0.2 * 0.5 * 0.5;  // s = 0.1: (1 − s/d)² = 1/4
  EXPECT_NEAR(F[0].x, -f0 * c, 1e-14);
  EXPECT_NEAR(F[0].y, -f0 * c, 1e-14);
  EXPECT_EQ(F[0].z, 0.0);
  EXPECT_NEAR(F[1].y, 2.0 * 3.0 * 0.2 * 1.25 * 1.25, 1e-13);  // 0.05 inside the wall: s = −0.05, still pushed out
  EXPECT_EQ(xyz(F[2]), kZero);
  for (std::size_t i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k) {
      auto Xp = X, Xm = X;
      Xp[i][k] += 1e-6;
      Xm[i][k] -= 1e-6;
      EXPECT_NEAR(-(contact.energy(Xp) - contact.energy(Xm)) / 2e-6, F[i][k], 1e-7) << i << " " << k;
    }
  ContactForce off(g, {0.2, 2.0, false, settings.shapes}, {0, 3}, {3.0});
  off.compute(X, F);
  EXPECT_EQ(xyz(F[0]), kZero);
}

TEST(ContactForce, CellListSearchEqualsBruteForceWithPeriodicImages) {
  for (double range : {0.3, 1.0, 2.5, 3.9}) {  // 3.9: one or two bins along the periodic axes
    Cloud c(11);
    auto contact = c.contact(range);
    const auto fast = contact.neighbours(c.X);
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < c.X.size(); ++i) {
      std::vector<std::size_t> slow;
      const auto membrane = [&](std::size_t n) {
        return std::upper_bound(c.offsets.begin(), c.offsets.end(), n) - c.offsets.begin();
      };
      for (std::size_t j = 0; j < c.X.size(); ++j)
        if (membrane(j) != membrane(i) && norm(minimum_image(c.grid, c.X[i], c.X[j])) < range) slow.push_back(j);
      EXPECT_EQ(fast[i], slow) << "range " << range << ", node " << i;
      pairs += slow.size();
    }
    EXPECT_GT(pairs, 0u) << "range " << range;
  }
}

// Compact "membranes" (balls of nodes) at random centres, some beyond the periodic ends and one wrapped node by node:
// the bounding-box test that skips far membranes must find exactly the pairs of the brute-force search.
TEST(ContactForce, BoundingBoxesKeepEveryPairOfCompactMembranes) {
  const Grid grid{{8, 10, 6}, {8.0, 10.0, 6.0}, {P, P, W}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<std::size_t> offsets{0};
  std::vector<Vec3> X;
  for (int m = 0; m < 14; ++m) {
    const Vec3 centre{9 * U(rng) - 0.5, 11 * U(rng) - 0.5, 1 + 4 * U(rng)};
    for (int n = 0; n < 30; ++n) {
      Vec3 x = centre + Vec3{U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5} * 1.4;
      if (m == 13) x[0] -= 8 * std::floor(x[0] / 8);  // each node wrapped into [0, 8)
      X.push_back(x);
    }
    offsets.push_back(X.size());
  }
  const auto membrane = [&](std::size_t n) {
    return std::upper_bound(offsets.begin(), offsets.end(), n) - offsets.begin();
  };
  for (double range : {0.3, 1.0}) {
    ContactForce contact(grid, {range, 1.0, false, {}}, offsets, std::vector<double>(offsets.size() - 1, 1.0));
    const auto fast = contact.neighbours(X);
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      std::vector<std::size_t> slow;
      for (std::size_t j = 0; j < X.size(); ++j)
        if (membrane(j) != membrane(i) && norm(minimum_image(grid, X[i], X[j])) < range) slow.push_back(j);
      EXPECT_EQ(fast[i], slow) << "range " << range << ", node " << i;
      pairs += slow.size();
    }
    EXPECT_GT(pairs, 0u) << "range " << range;
  }
}

TEST(ContactForce, RangeMustBeBelowHalfThePeriodicLength) {
  const Grid g({10, 10, 10}, {1.0, 1.0, 1.0}, {P, W, W});
  EXPECT_THROW(ContactForce(g, {0.5, 1.0, true, {}}, {0, 1}, {1.0}), InputError);
  EXPECT_NO_THROW(ContactForce(g, {0.49, 1.0, true, {}}, {0, 1}, {1.0}));
}

TEST(ContactForce, AreaModulusOfEachLaw) {
  EXPECT_NEAR(small_strain_area_modulus(NeoHookean(2.0)), 2.0, 1e-7);
  EXPECT_NEAR(small_strain_area_modulus(Yeoh(1.0, 0.3)), 6.0, 1e-7);
  EXPECT_NEAR(small_strain_area_modulus(Skalak(1.0, 10.0)), 10.5, 1e-6);
}

// Two capsules (radius a = 1.5 = 3 h, 642 nodes each, E_s = 10) 0.6 apart along x in a periodic box of fluid at
// rest, pushed into each other by uniform nodal forces, +-300 on each capsule in all (20 E_s a: they flatten against
// each other; without contact they come to 0.242 of each other, with it to 0.270).
std::string two_capsules_toml() {
  return R"([domain]
Lx = 12.0
Ly = 6.0
Lz = 6.0
[grid]
nx = 24
ny = 12
nz = 12
[fluid]
rho = 0.01
mu = 1.0
[time]
dt = 0.05
end = 2.0
[output]
fields_every = 0
[[membrane]]
radius = 1.5
center = [4.2, 3.0, 3.0]
Es = 10.0
mesh.level = 2
[[membrane]]
radius = 1.5
center = [7.8, 3.0, 3.0]
Es = 10.0
mesh.level = 2
)";
}

struct Approach {
  double min_gap = 1e300;  ///< smallest distance of two nodes of the two capsules over the run
  int inside = 0;          ///< steps at which a node of one capsule lay inside the other
};

Approach push_together(const std::vector<std::string>& sets) {
  const auto config = apply_scenario(run_schema().parse_string(two_capsules_toml(), "two capsules", sets));
  Simulation sim(config);
  for (std::size_t m = 0; m < 2; ++m) {
    const std::size_t n = sim.mesh(m).num_nodes();
    sim.set_applied_forces(m, std::vector<Vec3>(n, Vec3{(m == 0 ? 300.0 : -300.0) / double(n), 0, 0}));
  }
  Approach a;
  while (!sim.finished()) {
    sim.advance([](const std::string&) {});
    const std::vector<std::vector<Vec3>> X{sim.op().membrane_positions(0), sim.op().membrane_positions(1)};
    if (const auto gap = closest_foreign_nodes(sim.grid(), X, 1.5)) a.min_gap = std::min(a.min_gap, gap->distance);
    bool in = false;
    for (std::size_t m = 0; m < 2 && !in; ++m)
      for (const auto& p : X[1 - m])
        if (encloses(sim.mesh(m), X[m], p)) {
          in = true;
          break;
        }
    a.inside += in;
  }
  return a;
}

TEST(ContactRun, TwoCapsulesPushedTogetherStayApart) {
  const Approach with = push_together({});  // contact.range = h = 0.5
  EXPECT_EQ(with.inside, 0) << "steps with a node of one capsule inside the other";
  EXPECT_GT(with.min_gap, 0.5 * 0.5) << "closest approach " << with.min_gap;
  EXPECT_LT(with.min_gap, 0.5) << "the capsules should come within range";
  std::printf("closest approach of the two capsules: %.4g (contact.range 0.5)\n", with.min_gap);
}

// capsule_shear_quick with the default contact (range h; the capsule keeps > h from the walls) and without: the
// same run bitwise, since no node comes within range of a wall.
TEST(ContactRun, IsolatedCapsuleMovesBitwiseAsWithoutContact) {
  const std::vector<std::string> sets{"scenario.kt_end=0.25", "output.fields_every=0"};
  auto run = [&](std::vector<std::string> s) {
    s.insert(s.end(), sets.begin(), sets.end());
    Simulation sim(apply_scenario(run_schema().parse_file(scenario_file("capsule_shear_quick.toml"), s)));
    while (!sim.finished()) sim.advance([](const std::string&) {});
    EXPECT_GT(sim.step(), 3);
    std::vector<std::array<double, 3>> X;
    for (const auto& p : sim.op().membrane_positions(0)) X.push_back(xyz(p));
    return X;
  };
  const auto with = run({}), without = run({"contact.range=0"});
  EXPECT_EQ(with, without);
}

}  // namespace
