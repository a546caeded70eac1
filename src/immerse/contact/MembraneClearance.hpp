#pragma once
// Clearance between the membranes of an initial configuration (Simulation checks it before anything runs).
//
// Two membranes are too close when a node of one lies within `reach` (one grid cell: the delta function of
// eq. (8) would spread their forces onto the same cells) of a node of the other; distances along periodic axes
// are minimum images. The nodes are binned in a hash grid of cell size `reach`, so the search is linear in the
// number of nodes. Closed surfaces with no close nodes are either apart or nested; `encloses` tells which by the
// winding number of the surface around a point (the solid angles of the four flat sub-triangles of each six-node
// element, Van Oosterom & Strackee 1983), which is 1 inside and 0 outside. `self_intersection` finds two elements of
// one surface that cross: the flat sub-triangles are binned in a hash grid, and those of different elements that share
// no node are tested for an edge of one passing through the other (signs of tetrahedron volumes).
// Verified by the tests MembraneClearance.* (hash grid against brute force with periodic images, winding number,
// self-intersection).
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

struct NodePairGap {
  std::size_t membrane_a = 0, node_a = 0, membrane_b = 0, node_b = 0;  ///< membrane_a > membrane_b
  double distance = 0;
};

/// Calls `visit` for every pair of nodes of two different membranes closer than `reach` (once per pair, membrane_a >
/// membrane_b), found through a cell list of bins of size >= reach.
void for_each_foreign_pair(const Grid& grid, const std::vector<std::vector<Vec3>>& X, double reach,
                           const std::function<void(const NodePairGap&)>& visit);

/// The closest pair of nodes of two different membranes among those closer than `reach`; nullopt if there is none.
/// Ties go to the pair with the lowest membrane and node indices (the result does not depend on binning order).
std::optional<NodePairGap> closest_foreign_nodes(const Grid& grid, const std::vector<std::vector<Vec3>>& X, double reach);

/// Vector from b to a, by the minimum image along the grid's periodic axes.
Vec3 minimum_image(const Grid& grid, const Vec3& a, const Vec3& b);

/// Two elements (lower index first) whose flat sub-triangles cross, the lowest such pair; nullopt if none do.
std::optional<std::pair<std::size_t, std::size_t>> self_intersection(const Mesh& mesh, const std::vector<Vec3>& X);

/// Winding number test: true when p lies inside the closed surface `mesh` at positions X.
bool encloses(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& p);

}  // namespace immerse
