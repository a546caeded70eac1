#pragma once
// Checks of membrane node positions against the fluid domain, used before spreading (eq. 6)
// and interpolation (eq. 14). The arrays are the concatenated nodes of all membranes; errors
// name the index in that array, and the caller adds membrane, step and time.
// Verified by the tests NodeDiagnostics.MinWallDistance and IBCoupler.NodesBeyondAWallOrNonFiniteAreNamed.
#include <span>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

/// Throws SimulationError("node <l> at (x, y, z) is outside the fluid domain: ...") for the first
/// node that is non-finite or lies beyond a wall. Periodic axes accept any finite coordinate
/// (positions wrap around); a node exactly on a wall is inside.
void check_nodes_in_domain(const Grid& grid, std::span<const Vec3> X);

/// Closest approach of any node to any wall (+infinity when no axis has walls, or no nodes).
/// Checks the nodes first, as check_nodes_in_domain.
double min_wall_distance(const Grid& grid, std::span<const Vec3> X);

}  // namespace immerse
