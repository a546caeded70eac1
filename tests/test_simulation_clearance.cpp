// Clearance checks of an initial configuration (MembraneClearance): the hash-grid search for the closest nodes of
// two membranes equals a brute-force search (with periodic minimum images), the winding-number test tells
// inside from outside of a curved closed membrane, and the self-intersection search finds a folded surface.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/membrane/MeshGenerator.hpp"

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

// Sound surfaces (the sphere of the paper's level-4 mesh, 10,242 nodes, and a flattened ellipsoid) do not intersect
// themselves; the search over the level-4 mesh takes a small part of a run's start.
TEST(MembraneClearance, SoundSurfacesDoNotIntersectThemselves) {
  const Mesh sphere = icosahedral_sphere(4);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(self_intersection(sphere, sphere.nodes).has_value());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "self_intersection of " << sphere.num_nodes() << " nodes: " << seconds << " s\n";
  EXPECT_LT(seconds, 1.0);
  std::vector<Vec3> flat;
  for (const auto& p : octahedral_sphere(3).nodes) flat.push_back({p.x, p.y, 0.05 * p.z});
  EXPECT_FALSE(self_intersection(octahedral_sphere(3), flat).has_value());
}

// A cigar bent around an axis until its ends cross; the elements named are the lowest pair.
TEST(MembraneClearance, SurfaceBentThroughItselfIsFound) {
  const Mesh mesh = octahedral_sphere(3);
  std::vector<Vec3> X;
  for (const auto& p : mesh.nodes) {
    const double angle = p.x / 0.25, r = 0.25 + 0.2 * p.z;
    X.push_back({r * std::sin(angle), 0.2 * p.y, r * std::cos(angle)});
  }
  const auto pair = self_intersection(mesh, X);
  ASSERT_TRUE(pair.has_value());
  EXPECT_LT(pair->first, pair->second);
  // Moved back, the same mesh is sound again.
  EXPECT_FALSE(self_intersection(mesh, mesh.nodes).has_value());
}

}  // namespace

