#include "immerse/membrane/MeshGenerator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "immerse/core/Error.hpp"

namespace immerse {
namespace {

using Tri = std::array<int, 3>;

/// Index of the (sphere-projected) midpoint of edge (a, b), created once and shared by both neighbours.
class EdgeMidpoints {
 public:
  explicit EdgeMidpoints(std::vector<Vec3>& nodes) : nodes_(nodes) {}
  int operator()(int a, int b) {
    const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b));
    auto [it, inserted] = index_.try_emplace(key, static_cast<int>(nodes_.size()));
    if (inserted) nodes_.push_back(normalized(0.5 * (nodes_[a] + nodes_[b])));
    return it->second;
  }

 private:
  std::vector<Vec3>& nodes_;
  std::unordered_map<std::uint64_t, int> index_;
};

Mesh subdivided_sphere(std::vector<Vec3> nodes, std::vector<Tri> tris, int level) {
  for (int l = 0; l < level; ++l) {
    EdgeMidpoints mid(nodes);
    std::vector<Tri> finer;
    finer.reserve(4 * tris.size());
    for (const auto& [a, b, c] : tris) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      finer.push_back({a, ab, ca});
      finer.push_back({ab, b, bc});
      finer.push_back({ca, bc, c});
      finer.push_back({ab, bc, ca});
    }
    tris = std::move(finer);
  }
  Mesh mesh;
  EdgeMidpoints mid(nodes);
  mesh.elements.reserve(tris.size());
  for (const auto& [a, b, c] : tris) mesh.elements.push_back({a, b, c, mid(a, b), mid(b, c), mid(c, a)});
  mesh.nodes = std::move(nodes);
  return mesh;
}

}  // namespace

Mesh icosahedral_sphere(int level) {
  require(level >= 0 && level <= 6, "mesh.level", level, "an integer in 0..6 for the icosahedral sphere");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                      {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = normalized(p);
  // Faces counter-clockwise seen from outside.
  std::vector<Tri> f{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                     {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                     {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return subdivided_sphere(std::move(v), std::move(f), level);
}

Mesh octahedral_sphere(int level) {
  require(level >= 0 && level <= 7, "mesh.level", level, "an integer in 0..7 for the octahedral sphere");
  std::vector<Vec3> v{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<Tri> f{{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return subdivided_sphere(std::move(v), std::move(f), level);
}

}  // namespace immerse
