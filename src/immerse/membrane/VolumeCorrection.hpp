#pragma once
// Volume correction by a normal shift (in the manner of Sigüenza, Mendez et al. 2016, J. Comput. Phys. 322, 723):
// after an accepted step every node of a membrane moves along its unit normal n_i by one common distance s,
//   X_i <- X_i + s n_i,   s the root of  V(X + s n) = V0,
// found by Newton's method with dV/ds = sum_i dV/dX_i . n_i (the exact gradient of VolumeAreaConstraint.hpp); V is a
// cubic polynomial in s and the leak of one step small, so two or three iterations reach round-off. The node normal
// is the normalized sum, over the elements sharing the node, of the surface Jacobian vector J = a_xi x a_eta at the
// node (an area-weighted mean normal). The shift is applied outside the implicit step: it changes the positions by
// the leak of one step (O(dt) times the leak rate), so the scheme stays second order in time only up to that size.
// Verification: tests/test_membrane_constraint.cpp (V restored to round-off) and tests/test_run_restart.cpp.
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// Unit normal at each node: the normalized sum of J = a_xi x a_eta at the node over the elements sharing it.
std::vector<Vec3> area_weighted_normals(const Mesh& mesh, const std::vector<Vec3>& X);

/// Moves X along area_weighted_normals(mesh, X) by the common distance s that makes the volume V0 (to round-off)
/// and returns s (m). SimulationError when Newton's method does not converge.
double normal_shift(const Mesh& mesh, std::vector<Vec3>& X, double V0);

}  // namespace immerse
