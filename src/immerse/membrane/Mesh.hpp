#pragma once
// Mesh of six-node curved (quadratic) triangles on a closed surface (paper §3, Fig. 1, eq. 38).
//
// elements[e] = {v0, v1, v2, m01, m12, m20}: the three vertices, counter-clockwise seen from outside
// (so (x1 - x0) x (x2 - x0) points outward), then the mid-side nodes of edges 0-1, 1-2 and 2-0.
// This is also Gmsh's node order for its 6-node triangle (element type 9). Positions live in `nodes`
// (the configuration the mesh was built in); any other configuration (reference, current) is a separate
// std::vector<Vec3> indexed like `nodes` on the same connectivity.
#include <array>
#include <cstddef>
#include <vector>

#include "immerse/core/Vec3.hpp"

namespace immerse {

struct Mesh {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 6>> elements;

  std::size_t num_nodes() const { return nodes.size(); }
  std::size_t num_elements() const { return elements.size(); }
};

}  // namespace immerse
