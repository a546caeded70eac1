// VolumeAreaConstraint: the gradients of V and A against finite differences of Geometry's volume() and area() on a
// deformed ellipsoid, the force zero at V0 and A0, without net force or torque, an inflated sphere relaxing back
// towards V0. VolumeCorrection: the normal shift restores V0 to round-off.
#include <gtest/gtest.h>

#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"
#include "immerse/membrane/VolumeCorrection.hpp"

using namespace immerse;

namespace {

/// A sheared ellipsoid off the origin, with a wobble so that no symmetry hides an error.
std::vector<Vec3> deformed(const std::vector<Vec3>& X) {
  std::vector<Vec3> Y(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) {
    const Vec3& p = X[i];
    Y[i] = Vec3{1.3 * p.x + 0.2, 0.9 * p.y - 0.1, 0.8 * p.z + 0.1 * p.x + 0.3} * (1 + 0.05 * p.x * p.y);
  }
  return Y;
}

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const auto& x : v) m = std::max(m, norm(x));
  return m;
}

}  // namespace

TEST(VolumeAreaConstraint, GradientsEqualFiniteDifferencesOnADeformedEllipsoid) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> X = deformed(mesh.nodes);
  const SurfaceGradients g = surface_gradients(mesh.elements, X, true);
  EXPECT_NEAR(g.volume, volume(mesh, X), 1e-14 * g.volume);
  EXPECT_NEAR(g.area, area(mesh, X), 1e-14 * g.area);
  const double h = 1e-5;  // truncation error O(h^2) ~ 1e-10, round-off ~ 1e-16 V / h ~ 1e-11
  double err_V = 0, err_A = 0;
  for (std::size_t i = 0; i < X.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      const double x0 = X[i][d];
      X[i][d] = x0 + h;
      const double Vp = volume(mesh, X), Ap = area(mesh, X);
      X[i][d] = x0 - h;
      const double Vm = volume(mesh, X), Am = area(mesh, X);
      X[i][d] = x0;
      err_V = std::max(err_V, std::abs((Vp - Vm) / (2 * h) - g.d_volume[i][d]));
      err_A = std::max(err_A, std::abs((Ap - Am) / (2 * h) - g.d_area[i][d]));
    }
  EXPECT_LT(err_V, 1e-8 * max_norm(g.d_volume));
  EXPECT_LT(err_A, 1e-8 * max_norm(g.d_area));
}

TEST(VolumeAreaConstraint, ForceIsMinusTheEnergyGradient) {
  const Mesh mesh = icosahedral_sphere(1);
  const VolumeAreaConstraint c(mesh, mesh.nodes, {2.0, 3.0});
  std::vector<Vec3> X = deformed(mesh.nodes);
  std::vector<Vec3> F(X.size());
  c.add_force(X, F);
  const double h = 1e-6;
  double err = 0;
  for (std::size_t i = 0; i < X.size(); i += 7)
    for (int d = 0; d < 3; ++d) {
      const double x0 = X[i][d];
      X[i][d] = x0 + h;
      const double Ep = c.energy(X);
      X[i][d] = x0 - h;
      const double Em = c.energy(X);
      X[i][d] = x0;
      err = std::max(err, std::abs(-(Ep - Em) / (2 * h) - F[i][d]));
    }
  EXPECT_LT(err, 1e-7 * max_norm(F));
}

TEST(VolumeAreaConstraint, ZeroAtV0AndA0NoNetForceNorTorque) {
  const Mesh mesh = icosahedral_sphere(2);
  const std::vector<Vec3> X0 = deformed(mesh.nodes);
  Mesh at_X0 = mesh;
  at_X0.nodes = X0;
  const VolumeAreaConstraint c(at_X0, X0, {2.0, 3.0});
  EXPECT_EQ(c.volume0(), volume(mesh, X0));
  EXPECT_EQ(c.area0(), area(mesh, X0));
  std::vector<Vec3> F(X0.size());
  c.add_force(X0, F);
  // At V0, A0 only the round-off of the two summation orders is left: relative 1e-15 of the force at 1 % strain.
  std::vector<Vec3> X1 = X0, F1(X0.size());
  for (auto& x : X1) x *= 1.01;
  c.add_force(X1, F1);
  EXPECT_LT(max_norm(F), 1e-12 * max_norm(F1));

  Vec3 net, torque;
  double scale = 0;
  for (std::size_t i = 0; i < X1.size(); ++i) {
    net += F1[i];
    torque += cross(X1[i], F1[i]);
    scale += norm(F1[i]) * (1 + norm(X1[i]));
  }
  EXPECT_LT(norm(net), 1e-13 * scale);
  EXPECT_LT(norm(torque), 1e-13 * scale);
}

TEST(VolumeAreaConstraint, InflatedSphereRelaxesBackTowardsV0) {
  // A capsule stress-free in a sphere inflated by 5 % (its reference) whose constraint holds the volume V0 of the
  // unit sphere, moved by overdamped dynamics dX_i/dt = F_i / a_i (a_i the node areas).
  const Mesh mesh = icosahedral_sphere(1);
  const double inflate = std::cbrt(1.05), Es = 1e-3, kV = 1.0;
  std::vector<Vec3> reference = mesh.nodes;
  for (auto& x : reference) x *= inflate;
  const double V0 = volume(mesh, mesh.nodes);
  auto relax = [&](double k) {
    const ElasticMembrane m(mesh, reference, NeoHookean{Es}, {}, ForceMethod::Contour, {k, 0.0});
    std::vector<Vec3> X = reference, F;
    const double tau = 0.2 / (3 * kV);  // the volume mode decays by 0.8 per step: rate tau k_V A / V0 = 3 tau k_V
    for (int step = 0; step < 60; ++step) {
      m.compute_force(X, F);
      const auto a = node_area_weights(mesh, X);
      for (std::size_t i = 0; i < X.size(); ++i) X[i] += (tau / a[i]) * F[i];
    }
    return (volume(mesh, X) - V0) / V0;
  };
  const double without = relax(0.0), with = relax(kV);
  EXPECT_NEAR(without, 0.05, 1e-3);  // stress-free as inflated: nothing moves it
  EXPECT_LT(std::abs(with), 1e-3);   // at equilibrium k_V dV/V0 balances the elastic pressure ~ Es/R dV/V0
  EXPECT_GT(with, 0);                // from above: the elastic force resists the deflation
}

TEST(VolumeAreaConstraint, RejectsNegativeModuli) {
  const Mesh mesh = icosahedral_sphere(0);
  try {
    VolumeAreaConstraint(mesh, mesh.nodes, {-1.0, 0.0});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "volume_modulus = -1: must be finite and >= 0");
  }
  EXPECT_THROW(ElasticMembrane(mesh, mesh.nodes, NeoHookean{1.0}, {}, ForceMethod::Contour, {0.0, -2.0}), InputError);
}

TEST(VolumeCorrection, NormalShiftRestoresTheVolumeToRoundOff) {
  const Mesh mesh = icosahedral_sphere(2);
  const std::vector<Vec3> X0 = deformed(mesh.nodes);
  const double V0 = volume(mesh, X0);
  for (double leak : {0.96, 1.003, 1.0 - 1e-7}) {
    std::vector<Vec3> X = X0;
    for (auto& x : X) x = (x - Vec3{0.2, -0.1, 0.3}) * std::cbrt(leak) + Vec3{0.2, -0.1, 0.3};
    const double s = normal_shift(mesh, X, V0);
    EXPECT_LT(std::abs(volume(mesh, X) - V0), 1e-12 * V0) << leak;
    EXPECT_EQ(s > 0, leak < 1) << leak;
    // Every node moved by |s| along one direction.
    EXPECT_NEAR(norm(X[5] - (X0[5] - Vec3{0.2, -0.1, 0.3}) * std::cbrt(leak) - Vec3{0.2, -0.1, 0.3}), std::abs(s),
                1e-12);
  }
}
