#pragma once
// Membrane shapes as maps of the unit sphere's nodes (x̂, ŷ, ẑ), |x̂| = 1, followed by a rigid placement
// x -> rotation·x + translation:
//   Sphere          x = a x̂
//   Ellipsoid       x = (a x̂, b ŷ, c ẑ)                                               (eq. 43)
//   OblateSpheroid  x = (R x̂, R ŷ, (b/a) R ẑ), R = radius·(b/a)^(-1/3) keeps the volume of the sphere of
//                   radius `radius` (§4.2.2); then inclined by θ0 in the shear (x–z) plane: the disc's
//                   axis x̂ turns to (cos θ0, 0, sin θ0), ẑ to (-sin θ0, 0, cos θ0)
//   BiconcaveCell   the red blood cell of eq. (45), Z(R) = ±0.5 R0 sqrt(1 - ρ²) (C0 + C1 ρ² + C2 ρ⁴),
//                   ρ = R/R0 (the factor 0.5 R0 is part of eq. 45). With X = R0 x̂, Y = R0 ŷ one has
//                   ρ² = x̂² + ŷ² and sqrt(1 - ρ²) = |ẑ| on the unit sphere, so Z = 0.5 R0 ẑ (C0 + C1 ρ² + C2 ρ⁴)
//                   is a smooth map that keeps the sphere's nodes well spread over the rim.
// The stress-free reference configuration and the initial configuration are two node arrays on one
// connectivity: e.g. reference = map_sphere(Sphere{0.2}, unit), initial = map_sphere(Ellipsoid{...}, unit) (§4.1).
// Verified by: the tests Shape.* (oblate spheroid volume and inclination, eq. 45, shared connectivity) and the study
// sphere_geometry (ellipsoid of eq. 43 and red cell of eq. 45: volume, axes, area).
#include <variant>
#include <vector>

#include "immerse/core/Mat3.hpp"

namespace immerse {

struct Sphere {
  double radius = 1;
};
struct Ellipsoid {
  double a = 1, b = 1, c = 1;  ///< semi-axes along x, y, z
};
struct OblateSpheroid {
  double radius = 1;        ///< radius of the sphere of equal volume
  double aspect_ratio = 1;  ///< b/a in (0, 1]: short (z) over long (x, y) semi-axis
  double inclination = 0;   ///< θ0 [rad] of the long axis from x towards z
};
struct BiconcaveCell {
  double R0 = 3.91;  ///< cell radius (µm in the paper, §4.3)
  double C0 = 0.207161, C1 = 2.002558, C2 = -1.122762;
};

/// Rigid placement applied after the shape: x -> rotation·x + translation.
struct RigidTransform {
  Mat3 rotation = Mat3::identity();
  Vec3 translation;
};

struct Shape {
  std::variant<Sphere, Ellipsoid, OblateSpheroid, BiconcaveCell> form;
  RigidTransform placement;
};

/// Rotation by `angle` (right-handed) about the unit vector along `axis`.
Mat3 rotation_about(const Vec3& axis, double angle);

/// One-line InputError for a non-positive size, an aspect ratio outside (0, 1], a non-finite parameter or a
/// placement rotation that is not proper orthogonal.
void validate(const Shape& shape);

/// Positions of the shape's nodes, one per node of the unit sphere (validates the shape first).
std::vector<Vec3> map_sphere(const Shape& shape, const std::vector<Vec3>& unit_sphere_nodes);

}  // namespace immerse
