#pragma once
// Pointwise kernel of the discrete bending energy (DihedralBending.hpp): the signed dihedral angle across one edge of
// a triangulated surface and its exact gradient with respect to the four vertices involved.
//
// Edge (i, j), e = x_j - x_i; triangle T1 = (i, j, k) and triangle T2 = (j, i, l), both counter-clockwise seen from
// outside, with normals n1 = e x (x_k - x_i), n2 = (x_i - x_j) x (x_l - x_j) (lengths twice the areas). The angle
//
//   theta = atan2((n1 x n2).e/|e|, n1.n2)
//
// is 0 on a flat pair and positive where the surface is convex seen from outside (a sphere). Moving a vertex within
// the plane of a triangle does not turn its normal; moving it by d along that triangle's unit normal turns the
// normal about the edge by d g / h, h = |n|/|e| the height of the opposite vertex over the edge and g the rate of
// change across the edge of the vertex's linear shape function (1 at the opposite vertex, alpha - 1 at x_i, -alpha
// at x_j, alpha = (x_opp - x_i).e/|e|^2 the opposite vertex's position along the edge). Hence, with u_m = |e| n_m/|n_m|^2,
//
//   dtheta/dx_k = -u1,   dtheta/dx_l = -u2,
//   dtheta/dx_i = (1 - alpha1) u1 + (1 - alpha2) u2,   dtheta/dx_j = alpha1 u1 + alpha2 u2
//
// (Bridson, Marino & Fedkiw 2003, Proc. ACM SIGGRAPH/Eurographics Symposium on Computer Animation, 28; the gradients
// sum to zero). Checked against central differences in tests/test_dihedral_bending.cpp.
#include <array>
#include <cmath>

#include "immerse/core/Vec3.hpp"

namespace immerse::membrane_k {

struct DihedralAngle {
  double theta;                ///< signed angle (rad), in (-pi, pi]
  std::array<Vec3, 4> grad;    ///< dtheta/dx for x_i, x_j, x_k, x_l
};

/// The flat triangles' normals must not vanish (the caller checks elements first).
[[gnu::always_inline]] inline DihedralAngle dihedral_angle(const Vec3& xi, const Vec3& xj, const Vec3& xk,
                                                           const Vec3& xl) {
  const Vec3 e = xj - xi;
  const Vec3 n1 = cross(e, xk - xi), n2 = cross(xi - xj, xl - xj);
  const double e2 = dot(e, e), le = std::sqrt(e2);
  const double theta = std::atan2(dot(cross(n1, n2), e) / le, dot(n1, n2));
  const Vec3 u1 = n1 * (le / dot(n1, n1)), u2 = n2 * (le / dot(n2, n2));
  const double a1 = dot(xk - xi, e) / e2, a2 = dot(xl - xi, e) / e2;
  return {theta, {(1 - a1) * u1 + (1 - a2) * u2, a1 * u1 + a2 * u2, -1.0 * u1, -1.0 * u2}};
}

}  // namespace immerse::membrane_k
