// The Taylor parameters of diagnostics.csv on shapes whose answer is known: D_xz of the section by the plane of shear
// (ShearPlaneProfile.hpp), cut through the curved elements, and D_ellipsoid of the equivalent ellipsoid
// (Diagnostics.hpp), for a sphere, for ellipsoids of semi-axes a(1 + δ), a, a(1 − δ) (D = δ), tilted in the x-z plane,
// and for a sphere whose nodes are displaced normally at random (node-scale roughness).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/run/Diagnostics.hpp"
#include "immerse/scenario/ShearPlaneProfile.hpp"

using namespace immerse;

namespace {

constexpr double kRadius = 5e-6;

struct Taylor {
  double D_xz, D_ellipsoid, theta;
};

Taylor measure_taylor(const Mesh& mesh, const std::vector<Vec3>& X) {
  const MembraneGeometry g = measure(mesh, X);
  return {shear_plane_profile(mesh, X, g.centroid).D_xz, ellipsoid_deformation(g), inclination(g)};
}

/// The nodes of `mesh` (a unit sphere) on the ellipsoid of semi-axes a(1 + δ), a, a(1 − δ) turned by `tilt` about y.
std::vector<Vec3> ellipsoid(const Mesh& mesh, double delta, double tilt) {
  std::vector<Vec3> X;
  const double c = std::cos(tilt), s = std::sin(tilt);
  for (const Vec3& p : mesh.nodes) {
    const double x = kRadius * (1 + delta) * p.x, z = kRadius * (1 - delta) * p.z;
    X.push_back({c * x - s * z, kRadius * p.y, s * x + c * z});
  }
  return X;
}

}  // namespace

// Cut through each element's four flat sub-triangles, the 642-node sphere had D_xz = 1.7e-3 at rest; what is left
// is mostly the curved elements' own departure from the sphere.
TEST(ShearPlaneProfile, SphereAtRestHasNoDeformation) {
  for (int level : {2, 4}) {
    const Mesh mesh = icosahedral_sphere(level);
    const Taylor t = measure_taylor(mesh, ellipsoid(mesh, 0, 0));
    std::printf("[ShearPlaneProfile] sphere of %zu nodes: D_xz = %.2e, D_ellipsoid = %.2e\n", mesh.nodes.size(), t.D_xz,
                t.D_ellipsoid);
    EXPECT_LT(t.D_xz, level == 2 ? 1e-4 : 1e-5) << "level " << level;
    EXPECT_LT(t.D_ellipsoid, 1e-6) << "level " << level;
  }
}

TEST(ShearPlaneProfile, EllipsoidInThePlaneOfShearHasItsTaylorParameter) {
  const Mesh mesh = icosahedral_sphere(2);
  for (double delta : {0.001, 0.01, 0.1})
    for (double tilt : {0.0, 0.3, M_PI / 4}) {
      const Taylor t = measure_taylor(mesh, ellipsoid(mesh, delta, tilt));
      EXPECT_NEAR(t.D_xz, delta, 2e-4 + 0.01 * delta) << "delta " << delta << ", tilt " << tilt;
      EXPECT_NEAR(t.D_ellipsoid, delta, 1e-3 * delta) << "delta " << delta << ", tilt " << tilt;
      if (tilt > 0) {
        EXPECT_NEAR(t.theta, tilt, 1e-6) << "delta " << delta;
      }
    }
}

// Normal displacements of 0.2 % of the radius at the nodes raise D_xz, the extremes of the section, by about that;
// the ellipsoid's D averages them out.
TEST(ShearPlaneProfile, NodeScaleRoughnessBiasesTheSectionButNotTheEllipsoid) {
  const Mesh mesh = icosahedral_sphere(4);
  std::vector<Vec3> X = ellipsoid(mesh, 0.005, M_PI / 4);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  for (std::size_t i = 0; i < X.size(); ++i) X[i] = X[i] * (1 + u(random));
  const Taylor t = measure_taylor(mesh, X);
  EXPECT_GT(t.D_xz, 0.005 + 0.0005);
  EXPECT_NEAR(t.D_ellipsoid, 0.005, 2e-4);
}
