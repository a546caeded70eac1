// ElasticMembrane: input validation, inverted elements, determinism across thread counts, lumped areas;
// CurvatureFit accuracy.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <string>

#include "immerse/membrane/CurvatureFit.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/MeshGenerator.hpp"

using namespace immerse;

namespace {

std::vector<Vec3> ellipsoid(const std::vector<Vec3>& X) {
  std::vector<Vec3> Y(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) Y[i] = {1.3 * X[i].x, 0.9 * X[i].y, 0.8 * X[i].z + 0.1 * X[i].x};
  return Y;
}

}  // namespace

TEST(MembraneForce, RejectsBadInput) {
  const Mesh mesh = icosahedral_sphere(1);
  EXPECT_THROW(ElasticMembrane(mesh, std::vector<Vec3>(3), NeoHookean{1.0}, {}, ForceMethod::Contour), InputError);
  try {
    ElasticMembrane(mesh, mesh.nodes, NeoHookean{1.0}, {-1.0, ReferenceCurvature::Zero}, ForceMethod::Contour);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "membrane.bending.kappa_B = -1: must be finite and >= 0");
  }
  Mesh bad = mesh;
  bad.elements[5][2] = static_cast<int>(mesh.nodes.size());
  EXPECT_THROW(ElasticMembrane(bad, bad.nodes, NeoHookean{1.0}, {}, ForceMethod::Energy), InputError);
  // A degenerate reference element (a vertex collapsed onto another). Consistent outward orientation of the
  // whole mesh is checked by the mesh helper's MeshValidation, not here.
  std::vector<Vec3> collapsed = mesh.nodes;
  collapsed[mesh.elements[7][1]] = collapsed[mesh.elements[7][0]];
  try {
    ElasticMembrane(mesh, collapsed, NeoHookean{1.0}, {}, ForceMethod::Energy);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("membrane reference element "), std::string::npos) << e.what();
  }
  const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{1.0}, {}, ForceMethod::Contour);
  std::vector<Vec3> F;
  EXPECT_THROW(m.compute_force(std::vector<Vec3>(5), F), InputError);
}

TEST(MembraneForce, InvertedElementIsASimulationErrorNamingIt) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> X = mesh.nodes;
  const auto& el = mesh.elements[11];
  X[el[4]] = X[el[0]] + 3.0 * (X[el[4]] - X[el[0]]);  // push a mid-side node across the element: it folds
  for (ForceMethod method : {ForceMethod::Contour, ForceMethod::Energy}) {
    const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{1.0}, {}, method);
    std::vector<Vec3> F;
    try {
      m.compute_force(X, F);
      FAIL();
    } catch (const SimulationError& e) {
      EXPECT_NE(std::string(e.what()).find("element "), std::string::npos) << e.what();
    }
    X[el[4]].x = NAN;
    EXPECT_THROW(m.compute_force(X, F), SimulationError);
    EXPECT_THROW(m.compute_energy(X), SimulationError);
    X[el[4]] = mesh.nodes[el[0]] + 3.0 * (mesh.nodes[el[4]] - mesh.nodes[el[0]]);
  }
}

// A mid-side node slid along its edge past the quarter point: the Jacobian vanishes at the vertex it approaches
// while every quadrature point still sees a positive one. Both methods refuse the state (eq. (42) evaluates the
// element nodes anyway; the energy method checks them), so a time step cannot accept a corner-folded element.
TEST(MembraneForce, ElementFoldedAtAVertexIsRefusedByBothMethods) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> X = mesh.nodes;
  const auto& el = mesh.elements[11];
  const Vec3 mid = 0.5 * (X[el[0]] + X[el[1]]);
  X[el[3]] = mid - 0.28 * (X[el[1]] - X[el[0]]);  // 1 + 4 t = -0.12 at vertex 0 along the edge
  for (ForceMethod method : {ForceMethod::Contour, ForceMethod::Energy}) {
    const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{1.0}, {}, method);
    std::vector<Vec3> F;
    EXPECT_THROW(m.compute_force(X, F), SimulationError);
    EXPECT_NO_THROW(m.compute_energy(X));  // the quadrature points alone do not see it
  }
}

// A vertex pushed in by half the radius: the six elements around the dimple are strongly curved but nowhere folded
// (|J| stays above 0.3 of its largest value on each), and the plane through their three vertices tilts more than
// 90 degrees away from the surface at some of their nodes. The fold test measures the Jacobian against the
// element's own normal at its centroid, so both methods accept the state and give finite forces.
TEST(MembraneForce, CurvedElementsAroundADimpleAreNotTakenForFolds) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> X = mesh.nodes;
  const int v = mesh.elements[11][0];
  X[v] = 0.5 * X[v];
  for (ForceMethod method : {ForceMethod::Contour, ForceMethod::Energy}) {
    const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{1.0}, {}, method);
    std::vector<Vec3> F;
    ASSERT_NO_THROW(m.compute_force(X, F));
    for (const Vec3& f : F) EXPECT_TRUE(std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.z));
    EXPECT_GT(m.compute_energy(X), 0.0);
  }
}

TEST(MembraneForce, IdenticalForAnyThreadCount) {
  const Mesh mesh = icosahedral_sphere(2);
  const std::vector<Vec3> X = ellipsoid(mesh.nodes);
  for (ForceMethod method : {ForceMethod::Contour, ForceMethod::Energy}) {
    const ElasticMembrane m(mesh, mesh.nodes, Yeoh{0.5, 0.02}, {0.01, ReferenceCurvature::RestShape}, method);
    std::vector<Vec3> F1, F2;
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    m.compute_force(X, F1);
    const double E1 = m.compute_energy(X);
    omp_set_num_threads(2);
    m.compute_force(X, F2);
    const double E2 = m.compute_energy(X);
    omp_set_num_threads(saved);
    EXPECT_EQ(E1, E2);
    for (std::size_t i = 0; i < F1.size(); ++i) {
      EXPECT_EQ(F1[i].x, F2[i].x);
      EXPECT_EQ(F1[i].y, F2[i].y);
      EXPECT_EQ(F1[i].z, F2[i].z);
    }
  }
}

// Lumped areas are positive at every node (vertices too) and sum to the curved area, which converges to 4 pi
// at fourth order (quadratic surface); the rest state has zero energy.
TEST(MembraneForce, LumpedAreasAndRestEnergy) {
  std::vector<double> err;
  for (int level : {1, 2, 3}) {
    const Mesh mesh = icosahedral_sphere(level);
    const ElasticMembrane m(mesh, mesh.nodes, Skalak{0.3, 3.0}, {}, ForceMethod::Energy);
    const auto a = m.node_area(mesh.nodes);
    double S = 0, amin = INFINITY;
    for (double v : a) {
      S += v;
      amin = std::fmin(amin, v);
    }
    EXPECT_GT(amin, 0.2 * S / static_cast<double>(a.size()));
    err.push_back(std::fabs(S - 4 * M_PI));
    EXPECT_NEAR(m.compute_energy(mesh.nodes), 0, 1e-14);
  }
  EXPECT_GT(std::log2(err[1] / err[2]), 3.5) << err[0] << " " << err[1] << " " << err[2];
}

// Principal stretches and tensions of a uniaxially stretched sphere: lambda1 = 1.2 at the poles of the stretch
// axis is not uniform, but at the equator (x = 0) the hoop stretch along x is exactly 1.2 and along z 1.
TEST(MembraneForce, NodeStrainReportsPrincipalStretches) {
  const Mesh mesh = icosahedral_sphere(3);
  std::vector<Vec3> X = mesh.nodes;
  for (Vec3& x : X) x.x *= 1.2;
  const ElasticMembrane m(mesh, mesh.nodes, NeoHookean{3.0}, {}, ForceMethod::Contour);
  const auto s = m.node_strain(X);
  int checked = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (std::fabs(mesh.nodes[i].x) < 1e-12 && std::fabs(mesh.nodes[i].z) > 0.99) {  // on the great circle x = 0
      EXPECT_NEAR(s[i].lambda1, 1.2, 2e-3);
      EXPECT_NEAR(s[i].lambda2, 1.0, 2e-3);
      const double J = s[i].lambda1 * s[i].lambda2;  // neo-Hookean: tau1 = Gs (l1^2 - J^-2)/J, Gs = 1
      EXPECT_NEAR(s[i].tau1, (1.44 - 1 / (J * J)) / J, 1e-2);
      ++checked;
    }
  EXPECT_GT(checked, 0);
}

// CurvatureFit on an ellipsoid (semi-axes 1.3, 1, 0.7; nodes exactly on it): normal and mean curvature
// tr(kappa)/2 against the exact ones, max over the nodes, icosahedral levels 2-4. With F = x.D x - 1,
// D = diag(a^-2, b^-2, c^-2), p = D x: N = p/|p|, tr(kappa)/2 = (|p|^2 tr D - p.D p) / (2 |p|^3) (outward N).
// Expected orders: 4 (normal) and 3 (curvature, reached from level 3 on); also kappa is tangent: kappa N = 0.
TEST(MembraneForce, CurvatureFitConvergesOnEllipsoid) {
  const Vec3 axes{1.3, 1.0, 0.7};
  const Vec3 D{1 / (axes.x * axes.x), 1 / (axes.y * axes.y), 1 / (axes.z * axes.z)};
  std::vector<double> err_n, err_h;
  for (int level : {2, 3, 4}) {
    const Mesh mesh = icosahedral_sphere(level);
    std::vector<Vec3> X(mesh.nodes.size());
    for (std::size_t i = 0; i < X.size(); ++i)
      X[i] = {axes.x * mesh.nodes[i].x, axes.y * mesh.nodes[i].y, axes.z * mesh.nodes[i].z};
    const CurvatureFit fit(mesh, X);
    std::vector<Vec3> N;
    std::vector<Mat3> kappa;
    fit.compute(X, N, kappa);
    double en = 0, eh = 0, tangent = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      const Vec3 p{D.x * X[i].x, D.y * X[i].y, D.z * X[i].z};
      const double pp = dot(p, p), pDp = D.x * p.x * p.x + D.y * p.y * p.y + D.z * p.z * p.z;
      const double H = (pp * (D.x + D.y + D.z) - pDp) / (2 * pp * std::sqrt(pp));
      en = std::fmax(en, norm(N[i] - p / std::sqrt(pp)));
      eh = std::fmax(eh, std::fabs(0.5 * trace(kappa[i]) - H));
      tangent = std::fmax(tangent, norm(kappa[i] * N[i]));
    }
    err_n.push_back(en);
    err_h.push_back(eh);
    EXPECT_LT(tangent, 1e-12);
  }
  // Measured: normal 4.05, 3.87; mean curvature 2.07, 2.65 (3.01 from level 4 to 5).
  for (std::size_t k = 1; k < err_n.size(); ++k) {
    EXPECT_GT(std::log2(err_n[k - 1] / err_n[k]), 3.5) << "normal, level " << k + 2;
    EXPECT_GT(std::log2(err_h[k - 1] / err_h[k]), 2.0) << "mean curvature, level " << k + 2;
  }
  EXPECT_GT(std::log2(err_h[1] / err_h[2]), 2.5);
  EXPECT_LT(err_h.back(), 1e-3);
}

// A neighbourhood that cannot carry the quartic fit (here: the whole reference collapsed onto a line) is bad
// input naming the node.
TEST(MembraneForce, CurvatureFitRejectsDegenerateNeighbourhood) {
  const Mesh mesh = icosahedral_sphere(1);
  std::vector<Vec3> line(mesh.nodes.size());
  for (std::size_t i = 0; i < line.size(); ++i) line[i] = {static_cast<double>(i), 0, 0};
  try {
    const CurvatureFit fit(mesh, line);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "membrane mesh node 0: must be a neighbourhood that determines the quartic curvature fit "
                           "(well-shaped elements around it)");
  }
}
