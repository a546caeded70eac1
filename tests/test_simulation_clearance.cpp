// Clearance checks of an initial configuration (MembraneClearance): the hash-grid search for the closest nodes of
// two membranes equals a brute-force search (with periodic minimum images), and the winding-number test tells
// inside from outside of a curved closed membrane.
#include <gtest/gtest.h>

#include <random>

#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/simulation/MembraneClearance.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

std::optional<NodePairGap> brute_force(const Grid& g, const std::vector<std::vector<Vec3>>& X, double reach) {
  std::optional<NodePairGap> best;
  for (std::size_t m = 0; m < X.size(); ++m)
    for (std::size_t o = 0; o < m; ++o)
      for (std::size_t i = 0; i < X[m].size(); ++i)
        for (std::size_t j = 0; j < X[o].size(); ++j) {
          const double d = norm(minimum_image(g, X[m][i], X[o][j]));
          if (d < reach && (!best || d < best->distance)) best = NodePairGap{m, i, o, j, d};
        }
  return best;
}

TEST(MembraneClearance, HashGridSearchEqualsBruteForceWithPeriodicImages) {
  const Grid g({8, 10, 6}, {8.0, 10.0, 6.0}, {P, P, W});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  for (double reach : {0.3, 1.0, 2.5}) {
    std::vector<std::vector<Vec3>> X(4);
    for (auto& m : X)
      for (int i = 0; i < 60; ++i) m.push_back({8 * U(rng) - 0.5, 10 * U(rng) + 0.3, 6 * U(rng)});
    const auto fast = closest_foreign_nodes(g, X, reach), slow = brute_force(g, X, reach);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << "reach " << reach;
    if (!fast) continue;
    EXPECT_EQ(fast->distance, slow->distance);
    EXPECT_EQ(fast->membrane_a, slow->membrane_a);
    EXPECT_EQ(fast->node_a, slow->node_a);
    EXPECT_EQ(fast->membrane_b, slow->membrane_b);
    EXPECT_EQ(fast->node_b, slow->node_b);
  }
}

TEST(MembraneClearance, NodesNearOppositeEndsOfAPeriodicAxisAreClose) {
  const Grid g({10, 10, 10}, {1.0, 1.0, 1.0}, {P, W, W});
  const std::vector<std::vector<Vec3>> X{{{0.01, 0.5, 0.5}}, {{0.98, 0.5, 0.5}}};
  const auto gap = closest_foreign_nodes(g, X, 0.1);
  ASSERT_TRUE(gap.has_value());
  EXPECT_NEAR(gap->distance, 0.03, 1e-15);
  EXPECT_FALSE(closest_foreign_nodes(Grid({10, 10, 10}, {1.0, 1.0, 1.0}, {W, W, W}), X, 0.1).has_value());
}

TEST(MembraneClearance, WindingNumberTellsInsideFromOutside) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> X;
  for (const auto& p : mesh.nodes) X.push_back(2.0 * p + Vec3{1, 2, 3});
  EXPECT_TRUE(encloses(mesh, X, {1, 2, 3}));
  EXPECT_TRUE(encloses(mesh, X, {2.8, 2, 3}));
  EXPECT_FALSE(encloses(mesh, X, {3.2, 2, 3}));
  EXPECT_FALSE(encloses(mesh, X, {-5, 0, 0}));
}

}  // namespace
