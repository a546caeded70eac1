#include "immerse/membrane/VolumeAreaConstraint.hpp"

#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshElement.hpp"

namespace immerse {
namespace {

/// Shape values, parametric derivatives and weight at one quadrature point.
struct Point {
  std::array<double, 6> N, dxi, deta;
  double w;
};

constexpr Point point(double xi, double eta, double w) {
  return {MeshElement::shape(xi, eta), MeshElement::shape_dxi(xi, eta), MeshElement::shape_deta(xi, eta), w};
}

/// The volume's points: the 7-point rule on the element.
constexpr std::array<Point, 7> volume_points() {
  std::array<Point, 7> p{};
  for (std::size_t q = 0; q < 7; ++q) {
    const auto& g = MeshElement::quadrature[q];
    p[q] = point(g.xi, g.eta, g.weight);
  }
  return p;
}

/// The area's points: the 7-point rule mapped onto each of the four sub-triangles (v0 m01 m20), (m01 v1 m12),
/// (m20 m12 v2), (m01 m12 m20) of the parent triangle, as Geometry's area().
constexpr std::array<Point, 28> area_points() {
  constexpr std::array<std::array<int, 3>, 4> sub{{{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}}};
  std::array<Point, 28> p{};
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& p0 = MeshElement::node_coordinates[sub[k][0]];
    const auto& p1 = MeshElement::node_coordinates[sub[k][1]];
    const auto& p2 = MeshElement::node_coordinates[sub[k][2]];
    for (std::size_t q = 0; q < 7; ++q) {
      const auto& g = MeshElement::quadrature[q];
      p[7 * k + q] = point(p0[0] + g.xi * (p1[0] - p0[0]) + g.eta * (p2[0] - p0[0]),
                           p0[1] + g.xi * (p1[1] - p0[1]) + g.eta * (p2[1] - p0[1]), 0.25 * g.weight);
    }
  }
  return p;
}

constexpr auto kVolumePoints = volume_points();
constexpr auto kAreaPoints = area_points();

/// One element's share of V, A and of their gradients at its six nodes.
struct ElementPart {
  double V = 0, A = 0;
  std::array<Vec3, 6> dV, dA;
};

ElementPart element_part(const std::array<Vec3, 6>& x, bool with_area) {
  ElementPart e;
  for (const Point& p : kVolumePoints) {
    Vec3 r, a, b;
    for (int i = 0; i < 6; ++i) r += p.N[i] * x[i], a += p.dxi[i] * x[i], b += p.deta[i] * x[i];
    const Vec3 J = cross(a, b), bxr = cross(b, r), rxa = cross(r, a);
    const double w = p.w / 3;
    e.V += w * dot(r, J);
    for (int i = 0; i < 6; ++i) e.dV[i] += w * (p.N[i] * J + p.dxi[i] * bxr + p.deta[i] * rxa);
  }
  if (!with_area) return e;
  for (const Point& p : kAreaPoints) {
    Vec3 a, b;
    for (int i = 0; i < 6; ++i) a += p.dxi[i] * x[i], b += p.deta[i] * x[i];
    const Vec3 J = cross(a, b);
    const double j = norm(J);
    const Vec3 n = J / j, bxn = cross(b, n), nxa = cross(n, a);
    e.A += p.w * j;
    for (int i = 0; i < 6; ++i) e.dA[i] += p.w * (p.dxi[i] * bxn + p.deta[i] * nxa);
  }
  return e;
}

}  // namespace

SurfaceGradients surface_gradients(const std::vector<std::array<int, 6>>& elements, std::span<const Vec3> X,
                                   bool with_area) {
  Vec3 origin;
  for (const auto& x : X) origin += x;
  if (!X.empty()) origin = origin / static_cast<double>(X.size());
  std::vector<ElementPart> part(elements.size());
  const auto ne = static_cast<std::ptrdiff_t>(elements.size());
#pragma omp parallel for if (ne >= kMinElementsForThreads)
  for (std::ptrdiff_t e = 0; e < ne; ++e) {
    std::array<Vec3, 6> x;
    for (int i = 0; i < 6; ++i) x[i] = X[elements[e][i]] - origin;
    part[e] = element_part(x, with_area);
  }
  // Serial sums in element order: the result does not depend on the thread count.
  SurfaceGradients g;
  g.d_volume.assign(X.size(), Vec3{});
  if (with_area) g.d_area.assign(X.size(), Vec3{});
  for (std::size_t e = 0; e < elements.size(); ++e) {
    g.volume += part[e].V;
    g.area += part[e].A;
    for (int i = 0; i < 6; ++i) {
      g.d_volume[elements[e][i]] += part[e].dV[i];
      if (with_area) g.d_area[elements[e][i]] += part[e].dA[i];
    }
  }
  return g;
}

VolumeAreaConstraint::VolumeAreaConstraint(const Mesh& mesh, const std::vector<Vec3>& X0, ConstraintModuli moduli)
    : elements_(mesh.elements), moduli_(moduli) {
  require(std::isfinite(moduli_.volume) && moduli_.volume >= 0, "volume_modulus", moduli_.volume, "finite and >= 0");
  require(std::isfinite(moduli_.area) && moduli_.area >= 0, "area_modulus", moduli_.area, "finite and >= 0");
  V0_ = volume(mesh, X0);
  A0_ = area(mesh, X0);
  require(V0_ > 0, "membrane volume", V0_, "> 0 (a closed surface oriented outwards)");
}

void VolumeAreaConstraint::add_force(std::span<const Vec3> X, std::vector<Vec3>& F) const {
  const SurfaceGradients g = surface_gradients(elements_, X, moduli_.area > 0);
  const double cV = -moduli_.volume * (g.volume - V0_) / V0_;
  const double cA = moduli_.area > 0 ? -moduli_.area * (g.area - A0_) / A0_ : 0.0;
  for (std::size_t i = 0; i < F.size(); ++i) {
    F[i] += cV * g.d_volume[i];
    if (moduli_.area > 0) F[i] += cA * g.d_area[i];
  }
}

double VolumeAreaConstraint::energy(std::span<const Vec3> X) const {
  const SurfaceGradients g = surface_gradients(elements_, X, true);
  const double dV = g.volume - V0_, dA = g.area - A0_;
  return moduli_.volume * dV * dV / (2 * V0_) + moduli_.area * dA * dA / (2 * A0_);
}

}  // namespace immerse
