// MeanCurvatureBending and its kernel: the dihedral angle's gradient and the energy's gradient against central
// differences, the sphere's energy, a force-free rest shape, zero net force and torque, thread-count independence.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>

#include "immerse/membrane/DihedralAngle_K.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/MeanCurvatureBending.hpp"
#include "immerse/membrane/MeshGenerator.hpp"

using namespace immerse;

namespace {

std::vector<Vec3> ellipsoid(const std::vector<Vec3>& X) {
  std::vector<Vec3> Y(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) Y[i] = {1.3 * X[i].x, 0.9 * X[i].y, 0.8 * X[i].z + 0.1 * X[i].x};
  return Y;
}

double component(const Vec3& v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }
double& component(Vec3& v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }

}  // namespace

TEST(MeanCurvatureBending, DihedralAngleGradientMatchesCentralDifferences) {
  std::array<Vec3, 4> x{Vec3{0.1, -0.05, 0.02}, Vec3{1.0, 0.1, -0.03}, Vec3{0.45, 0.9, -0.3}, Vec3{0.6, -0.8, -0.5}};
  const auto d = membrane_k::dihedral_angle(x[0], x[1], x[2], x[3]);
  EXPECT_GT(d.theta, 0);  // both triangles fold down: convex seen from outside (+z side)
  const double h = 1e-6;
  Vec3 sum;
  for (int v = 0; v < 4; ++v) {
    sum += d.grad[v];
    for (int c = 0; c < 3; ++c) {
      auto p = x, m = x;
      component(p[v], c) += h;
      component(m[v], c) -= h;
      const double fd = (membrane_k::dihedral_angle(p[0], p[1], p[2], p[3]).theta -
                         membrane_k::dihedral_angle(m[0], m[1], m[2], m[3]).theta) / (2 * h);
      EXPECT_NEAR(component(d.grad[v], c), fd, 1e-8) << "vertex " << v << " component " << c;
    }
  }
  EXPECT_LT(norm(sum), 1e-14);
}

TEST(MeanCurvatureBending, ForceIsMinusTheEnergyGradient) {
  const Mesh mesh = icosahedral_sphere(1);
  for (auto ref : {ReferenceCurvature::Zero, ReferenceCurvature::RestShape}) {
    const MeanCurvatureBending b(mesh, mesh.nodes, {0.3, ref}, false);
    const std::vector<Vec3> X = ellipsoid(mesh.nodes);
    std::vector<Vec3> F(X.size());
    b.add_force(X, F);
    const double h = 1e-6;
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < X.size(); i += 7)
      for (int c = 0; c < 3; ++c) {
        std::vector<Vec3> p = X, m = X;
        component(p[i], c) += h;
        component(m[i], c) -= h;
        const double fd = -(b.energy(p) - b.energy(m)) / (2 * h);
        worst = std::max(worst, std::abs(component(F[i], c) - fd));
        scale = std::max(scale, std::abs(fd));
      }
    EXPECT_LT(worst, 1e-6 * scale);
  }
}

TEST(MeanCurvatureBending, SphereEnergyTendsToEightPiKappa) {
  // (kappa_B / 2) oint (2H)^2 dA = 8 pi kappa_B on any sphere; the error falls with the node spacing.
  double previous = 1;
  for (int level = 1; level <= 3; ++level) {
    const Mesh mesh = icosahedral_sphere(level);
    const MeanCurvatureBending b(mesh, mesh.nodes, {1.0, ReferenceCurvature::Zero}, false);
    const double err = std::abs(b.energy(mesh.nodes) / (8 * std::numbers::pi) - 1);
    EXPECT_LT(err, previous);
    previous = err;
  }
  EXPECT_LT(previous, 2e-3);
}

TEST(MeanCurvatureBending, RestShapeIsForceFreeAndForcesHaveNoNetForceOrTorque) {
  for (const Mesh& mesh : {icosahedral_sphere(2), octahedral_sphere(2)}) {
    const std::vector<Vec3> rest = ellipsoid(mesh.nodes);
    const MeanCurvatureBending b(mesh, rest, {0.2, ReferenceCurvature::RestShape}, false);
    std::vector<Vec3> F(rest.size());
    b.add_force(rest, F);
    double fmax = 0;
    for (const Vec3& f : F) fmax = std::max(fmax, norm(f));
    EXPECT_EQ(b.energy(rest), 0.0);
    EXPECT_LT(fmax, 1e-15);

    std::vector<Vec3> X = mesh.nodes, G(X.size());
    for (std::size_t i = 0; i < X.size(); ++i) X[i] += 0.05 * Vec3{std::sin(3.0 * static_cast<double>(i)), std::cos(5.0 * static_cast<double>(i)), 0.3};
    b.add_force(X, G);
    Vec3 net, torque;
    double gmax = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      net += G[i];
      torque += cross(X[i], G[i]);
      gmax = std::max(gmax, norm(G[i]));
    }
    const double n = static_cast<double>(X.size());
    EXPECT_LT(norm(net), 1e-12 * gmax * n);
    EXPECT_LT(norm(torque), 1e-12 * gmax * n);
  }
}

TEST(MeanCurvatureBending, ForcesDoNotDependOnTheThreadCount) {
  const Mesh mesh = icosahedral_sphere(4);  // large enough for threads
  const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{1.0}, {0.05, ReferenceCurvature::Zero}, ForceMethod::Energy);
  const std::vector<Vec3> X = ellipsoid(mesh.nodes);
  std::vector<Vec3> F1, F2;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  m.compute_force(X, F1);
  omp_set_num_threads(std::max(2, threads));
  m.compute_force(X, F2);
  omp_set_num_threads(threads);
  ASSERT_EQ(F1.size(), F2.size());
  for (std::size_t i = 0; i < F1.size(); ++i) {
    ASSERT_EQ(F1[i].x, F2[i].x) << "node " << i;
    ASSERT_EQ(F1[i].y, F2[i].y) << "node " << i;
    ASSERT_EQ(F1[i].z, F2[i].z) << "node " << i;
  }
}

TEST(MeanCurvatureBending, OppositelyOrientedNeighboursAreRefused) {
  Mesh mesh = icosahedral_sphere(1);
  auto& el = mesh.elements[3];
  el = {el[0], el[2], el[1], el[5], el[4], el[3]};  // one element flipped
  EXPECT_THROW(MeanCurvatureBending(mesh, mesh.nodes, {1.0, ReferenceCurvature::Zero}, false), InputError);
}
