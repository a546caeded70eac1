#include "immerse/membrane/Shape.hpp"

#include <cmath>

#include "immerse/core/Error.hpp"

namespace immerse {
namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

void require_positive(double v, const char* name) {
  require(std::isfinite(v) && v > 0, name, v, "a finite number > 0");
}

/// The shape's point for the unit-sphere point p, before the rigid placement.
Vec3 map_point(const Shape& shape, const Vec3& p) {
  return std::visit(
      Overloaded{
          [&](const Sphere& s) { return s.radius * p; },
          [&](const Ellipsoid& e) { return Vec3{e.a * p.x, e.b * p.y, e.c * p.z}; },
          [&](const OblateSpheroid& o) {
            const double R = o.radius / std::cbrt(o.aspect_ratio);
            const Vec3 x{R * p.x, R * p.y, o.aspect_ratio * R * p.z};
            const double c = std::cos(o.inclination), s = std::sin(o.inclination);
            return Vec3{c * x.x - s * x.z, x.y, s * x.x + c * x.z};
          },
          [&](const BiconcaveCell& b) {
            const double rho2 = p.x * p.x + p.y * p.y;  // (R/R0)², and sqrt(1 - rho2) = |ẑ|: eq. (45)
            return Vec3{b.R0 * p.x, b.R0 * p.y, 0.5 * b.R0 * p.z * (b.C0 + b.C1 * rho2 + b.C2 * rho2 * rho2)};
          },
      },
      shape.form);
}

}  // namespace

Mat3 rotation_about(const Vec3& axis, double angle) {
  const Vec3 u = normalized(axis);
  const double c = std::cos(angle), s = std::sin(angle);
  const Mat3 ux = Mat3::from_rows({0, -u.z, u.y}, {u.z, 0, -u.x}, {-u.y, u.x, 0});
  return c * Mat3::identity() + s * ux + (1 - c) * Mat3::outer(u, u);
}

void validate(const Shape& shape) {
  std::visit(Overloaded{
                 [](const Sphere& s) { require_positive(s.radius, "shape.radius"); },
                 [](const Ellipsoid& e) {
                   require_positive(e.a, "shape.a");
                   require_positive(e.b, "shape.b");
                   require_positive(e.c, "shape.c");
                 },
                 [](const OblateSpheroid& o) {
                   require_positive(o.radius, "shape.radius");
                   require(std::isfinite(o.aspect_ratio) && o.aspect_ratio > 0 && o.aspect_ratio <= 1,
                           "shape.aspect_ratio", o.aspect_ratio, "in (0, 1]");
                   require(std::isfinite(o.inclination), "shape.inclination", o.inclination, "finite");
                 },
                 [](const BiconcaveCell& b) {
                   require_positive(b.R0, "shape.R0");
                   require(std::isfinite(b.C0) && std::isfinite(b.C1) && std::isfinite(b.C2), "shape.C0, C1, C2",
                           "finite");
                   // Thickness 0.5 R0 (C0 + C1 t + C2 t²), t = ρ², must stay positive for 0 <= t < 1:
                   // check the ends and the interior extremum of the quadratic.
                   auto f = [&](double t) { return b.C0 + (b.C1 + b.C2 * t) * t; };
                   double fmin = std::fmin(f(0), f(1));
                   if (b.C2 > 0 && -b.C1 / (2 * b.C2) > 0 && -b.C1 / (2 * b.C2) < 1) fmin = f(-b.C1 / (2 * b.C2));
                   require(f(0) > 0 && fmin >= 0, "shape.C0, C1, C2",
                           "coefficients with C0 + C1 ρ² + C2 ρ⁴ > 0 for 0 <= ρ < 1 (positive thickness)");
                 },
             },
             shape.form);
  const Mat3& q = shape.placement.rotation;
  const Mat3 qtq = transpose(q) * q - Mat3::identity();
  require(std::sqrt(ddot(qtq, qtq)) < 1e-10 && det(q) > 0, "shape.rotation",
          "a proper rotation matrix (orthonormal, determinant +1)");
  require(isfinite(shape.placement.translation), "shape.translation", "finite");
}

std::vector<Vec3> map_sphere(const Shape& shape, const std::vector<Vec3>& unit_sphere_nodes) {
  validate(shape);
  std::vector<Vec3> x(unit_sphere_nodes.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = shape.placement.rotation * map_point(shape, unit_sphere_nodes[i]) + shape.placement.translation;
  return x;
}

}  // namespace immerse
