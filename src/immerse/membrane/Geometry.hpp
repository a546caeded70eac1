#pragma once
// Integral geometry of a closed surface of six-node curved triangles (eq. 38), by 7-point Gauss quadrature
// on each element (MeshElement). With the outward surface Jacobian J = X_ξ × X_η (n dA = J dξ dη):
//   area            S = ∮ dA
//   volume          V = (1/3) ∮ x·n dA                      (div x = 3)
//   first moment    ∫_V x dV = (1/4) ∮ x (x·n) dA         (div(x_i x) = 4 x_i)
//   second moment   ∫_V x xᵀ dV = (1/5) ∮ x xᵀ (x·n) dA   (div(x_i x_j x) = 5 x_i x_j)
// The volume integrand has degree 4 in (ξ, η), so V is exact for the curved elements; the moments carry a
// quadrature error far below the O(h⁴) error of the quadratic surface itself. The area integrand |J| is not a
// polynomial: it is integrated with the 7-point rule on each of the element's four sub-triangles (below), so
// that the node area weights sum exactly to it.
// Moments are taken about the mean node position to avoid cancellation for translated shapes.
//
// Equivalent ellipsoid: the inertia of the enclosed volume (unit density, about the volume centroid) is
// converted to the second-moment tensor M = ∫_V r rᵀ dV; a solid ellipsoid with semi-axes (a, b, c) has
// M = (V/5) diag(a², b², c²) in its principal frame, so semi-axis k = sqrt(5 λ_k / V) with λ_k, e_k the
// eigen-pairs of M (a 3×3 Jacobi eigen-solver). This is exact for an ellipsoid and the usual definition
// of the deformed capsule's axes otherwise.
//
// Node area weights: each element is split in parameter space into the four sub-triangles of its six
// nodes (v0 m01 m20), (m01 v1 m12), (m20 m12 v2), (m01 m12 m20); the curved area of each sub-triangle goes
// one third to each of its three nodes. The weights are positive at every node (unlike the integrals of
// the quadratic shape functions, which vanish at the vertices) and sum to the surface area S.
// Verified by: the study sphere_geometry (curved unit sphere area and volume at order ≥ 3, ellipsoid volume and
// axes, red cell volume and area) and the tests Geometry.*.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Mat3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

struct MembraneGeometry {
  double volume = 0, area = 0;
  Vec3 centroid;                       ///< volume centroid
  std::array<double, 3> semi_axes{};   ///< of the equivalent ellipsoid, largest first
  std::array<Vec3, 3> axes;            ///< unit principal directions matching semi_axes
};

/// Surface area of the curved surface with node positions X (same indexing as mesh.nodes).
double area(const Mesh& mesh, const std::vector<Vec3>& X);
/// Curved area of each element (the sum of its four sub-triangles' areas; they add up to area(mesh, X)).
std::vector<double> element_areas(const Mesh& mesh, std::span<const Vec3> X);
/// Least ratio of an element's area at X to its area in `reference_areas` (element_areas of the stress-free
/// reference), with the element that has it: the local area dilation J of the membrane law, at its lowest.
struct LeastAreaRatio {
  double ratio = 1;
  std::size_t element = 0;
};
LeastAreaRatio least_area_ratio(const Mesh& mesh, std::span<const Vec3> X, std::span<const double> reference_areas);
/// The same from the element areas already measured.
LeastAreaRatio least_area_ratio(std::span<const double> areas, std::span<const double> reference_areas);
/// Enclosed volume (positive for outward-oriented elements).
double volume(const Mesh& mesh, const std::vector<Vec3>& X);
/// Inertia tensor I = ∫_V (|r|² 1 - r rᵀ) dV of the enclosed volume with unit density, r from the
/// volume centroid.
Mat3 inertia_tensor(const Mesh& mesh, const std::vector<Vec3>& X);
/// Volume, area, centroid and equivalent-ellipsoid axes.
MembraneGeometry measure(const Mesh& mesh, const std::vector<Vec3>& X);
/// Nodal area weights (see the header comment); they sum to area(mesh, X).
std::vector<double> node_area_weights(const Mesh& mesh, const std::vector<Vec3>& X);

}  // namespace immerse
