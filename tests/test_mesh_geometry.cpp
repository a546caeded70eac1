// Curved-element geometry (eq. 38) and the membrane shapes (eqs. 43, 45, §4.2.2).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>
#include <numeric>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshElement.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/Shape.hpp"
#include "immerse/verify/Convergence.hpp"

using namespace immerse;
constexpr double pi = std::numbers::pi;

TEST(MeshElement, ShapeFunctionsInterpolateTheirNodesAndSumToOne) {
  for (int j = 0; j < 6; ++j) {
    const auto [xi, eta] = MeshElement::node_coordinates[j];
    const auto n = MeshElement::shape(xi, eta);
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(n[i], i == j ? 1.0 : 0.0, 1e-15);
  }
  for (const auto& q : MeshElement::quadrature) {
    const auto n = MeshElement::shape(q.xi, q.eta);
    const auto dx = MeshElement::shape_dxi(q.xi, q.eta), de = MeshElement::shape_deta(q.xi, q.eta);
    EXPECT_NEAR(std::accumulate(n.begin(), n.end(), 0.0), 1.0, 1e-15);
    EXPECT_NEAR(std::accumulate(dx.begin(), dx.end(), 0.0), 0.0, 1e-14);
    EXPECT_NEAR(std::accumulate(de.begin(), de.end(), 0.0), 0.0, 1e-14);
    // Derivatives against central differences (quadratics: exact up to rounding).
    const double h = 1e-5;
    const auto np = MeshElement::shape(q.xi + h, q.eta), nm = MeshElement::shape(q.xi - h, q.eta);
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(dx[i], (np[i] - nm[i]) / (2 * h), 1e-9);
  }
}

TEST(MeshElement, QuadratureIsExactForDegreeFive) {
  // ∫_T ξ^p η^q = p! q! / (p + q + 2)! on the parent triangle.
  auto fact = [](int n) { double f = 1; for (int k = 2; k <= n; ++k) f *= k; return f; };
  for (int p = 0; p <= 5; ++p)
    for (int q = 0; p + q <= 5; ++q) {
      double s = 0;
      for (const auto& g : MeshElement::quadrature) s += g.weight * std::pow(g.xi, p) * std::pow(g.eta, q);
      EXPECT_NEAR(s, fact(p) * fact(q) / fact(p + q + 2), 1e-15) << p << " " << q;
    }
}

TEST(Geometry, UnitSphereAreaAndVolumeConvergeAtFourthOrder) {
  std::vector<double> area_err, vol_err;
  for (int level = 1; level <= 4; ++level) {
    const Mesh m = icosahedral_sphere(level);
    area_err.push_back(std::fabs(area(m, m.nodes) - 4 * pi));
    vol_err.push_back(std::fabs(volume(m, m.nodes) - 4 * pi / 3));
  }
  const double pa = verify::min_observed_order(area_err), pv = verify::min_observed_order(vol_err);
  std::cout << "unit sphere, icosahedral levels 1-4: area order " << pa << ", volume order " << pv
            << ", level-4 errors " << area_err.back() << ", " << vol_err.back() << "\n";
  EXPECT_GT(pa, 3.7);
  EXPECT_GT(pv, 3.7);
}

TEST(Geometry, FlatElementsGiveExactPolyhedronVolumeAndArea) {
  // Straight mid-side nodes: the level-0 octahedron with flat faces has V = 4/3 and S = 4√3.
  Mesh m = octahedral_sphere(0);
  for (const auto& el : m.elements)
    for (int k = 0; k < 3; ++k) m.nodes[el[3 + k]] = 0.5 * (m.nodes[el[k]] + m.nodes[el[(k + 1) % 3]]);
  EXPECT_NEAR(volume(m, m.nodes), 4.0 / 3.0, 1e-15);
  EXPECT_NEAR(area(m, m.nodes), 4 * std::sqrt(3.0), 1e-14);
  const Mat3 I = inertia_tensor(m, m.nodes);  // octahedron: I = (V/10)·2 per axis for |x|+|y|+|z| <= 1
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(I(i, j), i == j ? 4.0 / 3.0 / 5.0 : 0.0, 1e-14);
}

TEST(Geometry, RotatedEllipsoidGivesItsAxesCentroidAndInertia) {
  const Mesh m = icosahedral_sphere(4);
  const Mat3 Q = rotation_about({1, -2, 0.5}, 1.1);
  const Vec3 c{0.3, -0.2, 0.7};
  const double a = 0.25, b = 0.22, cc = 0.2;
  const auto X = map_sphere(Shape{Ellipsoid{a, b, cc}, {Q, c}}, m.nodes);
  const MembraneGeometry g = measure(m, X);
  const double V = 4 * pi / 3 * a * b * cc;
  EXPECT_NEAR(g.volume / V - 1, 0.0, 1e-6);
  EXPECT_NEAR(norm(g.centroid - c), 0.0, 1e-14);
  const std::array<double, 3> exact{a, b, cc};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(g.semi_axes[k], exact[k], 2e-7);
    EXPECT_NEAR(std::fabs(dot(g.axes[k], Q.col(k))), 1.0, 1e-9);  // principal direction = rotated axis k
  }
  // Solid-ellipsoid inertia in the body frame: I = (V/5) diag(b²+c², a²+c², a²+b²).
  const Mat3 body = transpose(Q) * inertia_tensor(m, X) * Q;
  EXPECT_NEAR(body(0, 0), V / 5 * (b * b + cc * cc), 1e-6 * V * a * a);
  EXPECT_NEAR(body(1, 1), V / 5 * (a * a + cc * cc), 1e-6 * V * a * a);
  EXPECT_NEAR(body(2, 2), V / 5 * (a * a + b * b), 1e-6 * V * a * a);
  EXPECT_NEAR(body(0, 1), 0.0, 1e-8 * V * a * a);
}

TEST(Geometry, NodeAreaWeightsArePositiveAndSumToTheArea) {
  const Mesh m = octahedral_sphere(3);
  const auto X = map_sphere(Shape{BiconcaveCell{}, {}}, m.nodes);
  const auto w = node_area_weights(m, X);
  for (double x : w) EXPECT_GT(x, 0.0);
  EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0) / area(m, X), 1.0, 1e-14);
  // On a uniform flat patch the weight of an interior node is one third of its neighbouring sub-triangles:
  // the level-0 octahedron's vertex weight = 4 sub-triangles × (face area / 4) / 3.
  Mesh flat = octahedral_sphere(0);
  for (const auto& el : flat.elements)
    for (int k = 0; k < 3; ++k) flat.nodes[el[3 + k]] = 0.5 * (flat.nodes[el[k]] + flat.nodes[el[(k + 1) % 3]]);
  const auto wf = node_area_weights(flat, flat.nodes);
  const double face = std::sqrt(3.0) / 2;
  EXPECT_NEAR(wf[0], 4 * face / 4 / 3, 1e-15);                 // vertex: one corner sub-triangle per face
  EXPECT_NEAR(wf[flat.elements[0][3]], 6 * face / 4 / 3, 1e-15);  // mid-side node: three per face, two faces
}

TEST(Geometry, LeastAreaRatioIsTheLocalDilationAndNamesItsElement) {
  const Mesh m = icosahedral_sphere(2);
  const auto ref = element_areas(m, m.nodes);
  EXPECT_NEAR(std::accumulate(ref.begin(), ref.end(), 0.0) / area(m, m.nodes), 1.0, 1e-14);
  // A uniform stretch by lambda multiplies every element's area by lambda^2.
  std::vector<Vec3> X = m.nodes;
  for (auto& x : X) x *= 1.3;
  EXPECT_NEAR(least_area_ratio(m, X, ref).ratio, 1.69, 1e-13);
  // Pulling one element's mid-side nodes onto the centroid of its vertices shrinks it below its neighbours:
  // the sub-triangles (v0 m01 m20), (m01 v1 m12), (m20 m12 v2) keep a third of the flat triangle and (m01 m12 m20)
  // vanishes, while the elements sharing those mid-side nodes grow.
  const std::size_t e = 17;
  const auto& el = m.elements[e];
  const Vec3 c = (m.nodes[el[0]] + m.nodes[el[1]] + m.nodes[el[2]]) / 3.0;
  X = m.nodes;
  for (int k = 3; k < 6; ++k) X[el[k]] = c;
  const LeastAreaRatio least = least_area_ratio(m, X, ref);
  EXPECT_EQ(least.element, e);
  const double flat = 0.5 * norm(cross(m.nodes[el[1]] - m.nodes[el[0]], m.nodes[el[2]] - m.nodes[el[0]]));
  EXPECT_LT(least.ratio, flat / ref[e]);
  EXPECT_GT(least.ratio, 0.0);
}

TEST(Geometry, ResultsDoNotDependOnTheThreadCount) {
  const Mesh m = icosahedral_sphere(4);
  const auto X = map_sphere(Shape{Ellipsoid{1.0, 0.8, 0.6}, {}}, m.nodes);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const MembraneGeometry g1 = measure(m, X);
  const auto w1 = node_area_weights(m, X);
  omp_set_num_threads(3);
  const MembraneGeometry g3 = measure(m, X);
  const auto w3 = node_area_weights(m, X);
  omp_set_num_threads(threads);
  EXPECT_EQ(g1.volume, g3.volume);
  EXPECT_EQ(g1.area, g3.area);
  EXPECT_EQ(g1.semi_axes, g3.semi_axes);
  EXPECT_EQ(w1, w3);
}

TEST(Shape, OblateSpheroidKeepsTheVolumeAndIsInclinedInTheShearPlane) {
  const Mesh m = icosahedral_sphere(4);
  const double theta = pi / 4, ratio = 0.5, radius = 1.3;
  const MembraneGeometry g = measure(m, map_sphere(Shape{OblateSpheroid{radius, ratio, theta}, {}}, m.nodes));
  EXPECT_NEAR(g.volume / (4 * pi / 3 * std::pow(radius, 3)), 1.0, 1e-5);
  EXPECT_NEAR(g.semi_axes[2] / g.semi_axes[0], ratio, 1e-6);
  EXPECT_NEAR(g.semi_axes[0], g.semi_axes[1], 1e-6);
  // The short axis lies in the x–z plane, turned from z by θ0 towards -x.
  EXPECT_NEAR(std::fabs(dot(g.axes[2], {-std::sin(theta), 0, std::cos(theta)})), 1.0, 1e-9);
}

TEST(Shape, BiconcaveCellMatchesEquation45) {
  // Profile along the unit circle in the x–z plane: thickness 2Z at R, compared with the notes:
  // 0.81 µm at the centre, a maximum of 2.566 µm at R = 2.738 µm.
  std::vector<Vec3> circle;
  const int n = 20000;
  for (int i = 0; i <= n; ++i) {
    const double phi = 0.5 * pi * i / n;  // from the pole (R = 0) to the rim
    circle.push_back({std::sin(phi), 0, std::cos(phi)});
  }
  const auto p = map_sphere(Shape{BiconcaveCell{}, {}}, circle);
  EXPECT_NEAR(2 * p.front().z, 0.81, 5e-4);
  std::size_t imax = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i].z > p[imax].z) imax = i;
  EXPECT_NEAR(2 * p[imax].z, 2.566, 5e-4);
  EXPECT_NEAR(p[imax].x, 2.738, 1e-3);
  EXPECT_NEAR(p.back().x, 3.91, 1e-12);
  // Eq. (45) itself at a few radii.
  const BiconcaveCell b;
  for (std::size_t i = 1000; i < p.size(); i += 4000) {
    const double r = p[i].x / b.R0;
    const double Z = 0.5 * b.R0 * std::sqrt(1 - r * r) * (b.C0 + b.C1 * r * r + b.C2 * r * r * r * r);
    EXPECT_NEAR(p[i].z, Z, 1e-12);
  }

  // Volume and area of the curved mesh against the axisymmetric integrals of the same profile
  // (Simpson in the polar angle, converged to ~1e-12): V = 2∫ 2πR Z dR, S = 2∫ 2πR |dX/dφ| dφ.
  double V = 0, S = 0;
  for (std::size_t i = 0; i + 1 < circle.size(); ++i) {
    const double dphi = 0.5 * pi / n;
    const auto f = [&](double phi) {
      const auto q = map_sphere(Shape{BiconcaveCell{}, {}}, {{std::sin(phi), 0, std::cos(phi)}})[0];
      const double h = 1e-6;
      const auto qp = map_sphere(Shape{BiconcaveCell{}, {}}, {{std::sin(phi + h), 0, std::cos(phi + h)}})[0];
      const auto qm = map_sphere(Shape{BiconcaveCell{}, {}}, {{std::sin(phi - h), 0, std::cos(phi - h)}})[0];
      const Vec3 d = (qp - qm) / (2 * h);
      return std::array<double, 2>{4 * pi * q.x * q.z * d.x, 4 * pi * q.x * norm(d)};
    };
    const double phi0 = 0.5 * pi * static_cast<double>(i) / n;
    const auto f0 = f(phi0), f1 = f(phi0 + dphi / 2), f2 = f(phi0 + dphi);
    V += dphi / 6 * (f0[0] + 4 * f1[0] + f2[0]);
    S += dphi / 6 * (f0[1] + 4 * f1[1] + f2[1]);
  }
  std::vector<double> vol_err, area_err;
  for (int level = 2; level <= 5; ++level) {
    const Mesh m = octahedral_sphere(level);
    const MembraneGeometry g = measure(m, map_sphere(Shape{BiconcaveCell{}, {}}, m.nodes));
    vol_err.push_back(std::fabs(g.volume - V) / V);
    area_err.push_back(std::fabs(g.area - S) / S);
  }
  std::cout << "RBC profile integrals V = " << V << " um^3, S = " << S << " um^2; mesh level 5 rel. errors "
            << vol_err.back() << ", " << area_err.back() << "; orders " << verify::min_observed_order(vol_err)
            << ", " << verify::min_observed_order(area_err) << "\n";
  EXPECT_NEAR(V, 94.09, 0.005);
  EXPECT_NEAR(S, 134.09, 0.005);
  EXPECT_LT(vol_err.back(), 1e-6);
  EXPECT_LT(area_err.back(), 1e-6);
  EXPECT_GT(verify::min_observed_order(vol_err), 3.0);
  EXPECT_GT(verify::min_observed_order(area_err), 3.0);
}

TEST(Shape, ReferenceAndInitialConfigurationsShareTheConnectivity) {
  // §4.1: initial ellipsoid (0.25, 0.22, 0.2) stretched from a stress-free sphere of radius 0.2.
  const Mesh m = octahedral_sphere(3);
  const auto reference = map_sphere(Shape{Sphere{0.2}, {}}, m.nodes);
  const auto initial = map_sphere(Shape{Ellipsoid{0.25, 0.22, 0.2}, {}}, m.nodes);
  ASSERT_EQ(reference.size(), m.num_nodes());
  ASSERT_EQ(initial.size(), m.num_nodes());
  EXPECT_NEAR(volume(m, reference) / (4 * pi / 3 * 0.008), 1.0, 1e-3);
  EXPECT_NEAR(std::cbrt(volume(m, initial) * 3 / (4 * pi)), 0.2224, 1e-4);  // equilibrium radius (abc)^(1/3)
}

TEST(Shape, RejectsBadParametersWithOneLineMessages) {
  const std::vector<Vec3> p{{0, 0, 1}};
  auto message = [&](const Shape& s) {
    try {
      map_sphere(s, p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(Shape{Sphere{-1}, {}}), "shape.radius = -1: must be a finite number > 0");
  EXPECT_EQ(message(Shape{Ellipsoid{1, 0, 1}, {}}), "shape.b = 0: must be a finite number > 0");
  EXPECT_EQ(message(Shape{OblateSpheroid{1, 1.5, 0}, {}}), "shape.aspect_ratio = 1.5: must be in (0, 1]");
  EXPECT_EQ(message(Shape{OblateSpheroid{1, 0, 0}, {}}), "shape.aspect_ratio = 0: must be in (0, 1]");
  EXPECT_NE(message(Shape{BiconcaveCell{3.91, 0.2, -1, 0}, {}}).find("positive thickness"), std::string::npos);
  EXPECT_NE(message(Shape{Sphere{1}, {2 * Mat3::identity(), {}}}).find("shape.rotation"), std::string::npos);
  EXPECT_NE(message(Shape{Sphere{1}, {Mat3::identity(), {NAN, 0, 0}}}).find("shape.translation"), std::string::npos);
  EXPECT_EQ(message(Shape{Sphere{1}, {rotation_about({0, 1, 0}, 0.3), {1, 2, 3}}}), "");
}
