#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/MeshValidation.hpp"

using namespace immerse;

namespace {

struct Count {
  int level;
  std::size_t nodes, elements;
};

void expect_closed_outward_sphere(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& e : m.elements) {
    const Vec3 n = cross(m.nodes[e[1]] - m.nodes[e[0]], m.nodes[e[2]] - m.nodes[e[0]]);
    EXPECT_GT(dot(n, m.nodes[e[0]] + m.nodes[e[1]] + m.nodes[e[2]]), 0.0);  // outward
    for (int k = 0; k < 3; ++k) ++directed[{e[k], e[(k + 1) % 3]}];
  }
  for (const auto& [edge, uses] : directed) {
    EXPECT_EQ(uses, 1);  // consistent orientation: each directed edge once, its reverse once
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  for (const auto& x : m.nodes) EXPECT_NEAR(norm(x), 1.0, 1e-14);
}

}  // namespace

TEST(MeshGenerator, IcosahedralCountsAreExact) {
  for (const Count c : {Count{0, 42, 20}, Count{2, 642, 320}, Count{3, 2562, 1280}, Count{4, 10242, 5120}}) {
    const Mesh m = icosahedral_sphere(c.level);
    EXPECT_EQ(m.num_nodes(), c.nodes) << "level " << c.level;
    EXPECT_EQ(m.num_elements(), c.elements) << "level " << c.level;
  }
}

TEST(MeshGenerator, OctahedralCountsAreExact) {
  for (const Count c : {Count{2, 258, 128}, Count{3, 1026, 512}, Count{4, 4098, 2048}, Count{5, 16386, 8192}}) {
    const Mesh m = octahedral_sphere(c.level);
    EXPECT_EQ(m.num_nodes(), c.nodes) << "level " << c.level;
    EXPECT_EQ(m.num_elements(), c.elements) << "level " << c.level;
  }
}

TEST(MeshGenerator, ElementsAreOutwardConsistentAndOnTheSphere) {
  expect_closed_outward_sphere(icosahedral_sphere(1));
  expect_closed_outward_sphere(octahedral_sphere(2));
}

TEST(MeshGenerator, MidSideNodesSitBetweenTheirVertices) {
  const Mesh m = icosahedral_sphere(2);
  for (const auto& e : m.elements)
    for (int k = 0; k < 3; ++k) {
      const Vec3 expected = normalized(0.5 * (m.nodes[e[k]] + m.nodes[e[(k + 1) % 3]]));
      EXPECT_NEAR(norm(m.nodes[e[3 + k]] - expected), 0.0, 1e-15);
    }
}

TEST(MeshGenerator, RejectsLevelsOutOfRange) {
  EXPECT_THROW(icosahedral_sphere(7), InputError);
  EXPECT_THROW(octahedral_sphere(-1), InputError);
  try {
    octahedral_sphere(8);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.level = 8"), std::string::npos) << e.what();
  }
}

TEST(MeshGenerator, GeneratedMeshesAreValidClosedMeshes) {
  for (int level = 0; level <= 3; ++level) {
    EXPECT_NO_THROW(validate_closed_mesh(icosahedral_sphere(level), "icosahedral"));
    EXPECT_NO_THROW(validate_closed_mesh(octahedral_sphere(level), "octahedral"));
  }
}
