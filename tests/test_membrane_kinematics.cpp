// Single-element kinematics (paper eqs. 17-20, 39, 40) on hand-made six-node elements.
#include <gtest/gtest.h>

#include <cmath>

#include "immerse/membrane/MaterialLaw.hpp"
#include "immerse/membrane/MembraneKinematics_K.hpp"

using namespace immerse;
using membrane_k::Nodes;

namespace {

/// A curved element cut from a sphere of radius R (vertices and projected mid-side nodes), counter-clockwise
/// seen from outside.
Nodes sphere_patch(double R) {
  const Vec3 v0 = normalized(Vec3{0.1, -0.05, 1}), v1 = normalized(Vec3{0.45, 0.1, 0.9}),
             v2 = normalized(Vec3{0.05, 0.4, 0.95});
  return {R * v0, R * v1, R * v2, R * normalized(v0 + v1), R * normalized(v1 + v2), R * normalized(v2 + v0)};
}

Nodes flat_element() { return {{{0, 0, 0}, {1, 0.1, 0}, {0.2, 0.9, 0}, {0.5, 0.05, 0}, {0.6, 0.5, 0}, {0.1, 0.45, 0}}}; }

double max_diff(const Mat3& a, const Mat3& b) {
  double m = 0;
  for (int i = 0; i < 9; ++i) m = std::fmax(m, std::fabs(a.a[i] - b.a[i]));
  return m;
}

Nodes map(const Nodes& x, const Mat3& F, const Vec3& c) {
  Nodes y;
  for (int i = 0; i < 6; ++i) y[i] = F * x[i] + c;
  return y;
}

}  // namespace

// Eq. (39) in closed form, A = a_alpha (x) abar^alpha, equals the solution of the 3x3 system, and for an
// affine motion X = F Xbar + c it is F restricted to the reference tangent plane: A = F Pbar.
TEST(MembraneKinematics, DeformationGradientSolvesEq39) {
  const Nodes xr = sphere_patch(2.0);
  const Mat3 F = Mat3::from_rows({1.2, 0.1, -0.3}, {0.05, 0.9, 0.2}, {0.3, -0.1, 1.1});
  const Nodes x = map(xr, F, {0.3, -2, 5});
  for (const auto& p : tri6::kNodePoints) {
    const tri6::Shape s = tri6::shape(p.xi, p.eta);
    const auto tr = membrane_k::tangents(xr, s), t = membrane_k::tangents(x, s);
    const auto fr = membrane_k::frame(tr);
    const Mat3 A = membrane_k::deformation_gradient(t, fr);
    // Solve A [abar_xi abar_eta nbar] = [a_xi a_eta 0] directly.
    const Mat3 Mbar = transpose(Mat3::from_rows(tr.a_xi, tr.a_eta, fr.n));
    const Mat3 rhs = transpose(Mat3::from_rows(t.a_xi, t.a_eta, {0, 0, 0}));
    EXPECT_LT(max_diff(A, rhs * inverse(Mbar)), 1e-14);
    EXPECT_LT(max_diff(A, F * (Mat3::identity() - Mat3::outer(fr.n, fr.n))), 1e-14);
    // B = A A^T through the reference metric (17); invariants (19), (20).
    const auto g = membrane_k::ref_metric(tr);
    const Mat3 B = membrane_k::left_cauchy_green(t, g).full();
    EXPECT_LT(max_diff(B, A * transpose(A)), 1e-14);
    const auto inv = membrane_k::invariants(t, membrane_k::frame(t).J, g);
    const double trB = trace(B), trB2 = trace(B * B);
    EXPECT_NEAR(inv.A1, 0.5 * std::log(0.5 * (trB * trB - trB2)), 1e-14);
    EXPECT_NEAR(inv.A2, 0.5 * trB - 1, 1e-14);
  }
}

// Pure in-plane stretch of a flat element: A1 = ln(l1 l2), A2 = (l1^2 + l2^2)/2 - 1 and the neo-Hookean
// principal tensions tau_i = (Es/3) (l_i^2 - (l1 l2)^-2) / (l1 l2) along x and y.
TEST(MembraneKinematics, PlanarStretchInvariantsAndTension) {
  const double l1 = 1.3, l2 = 0.85, Es = 2.0;
  const Nodes xr = flat_element();
  const Nodes x = map(xr, Mat3::from_rows({l1, 0, 0}, {0, l2, 0}, {0, 0, 1}), {});
  const NeoHookean law{Es};
  for (const auto& p : tri6::kNodePoints) {
    const tri6::Shape s = tri6::shape(p.xi, p.eta);
    const auto t = membrane_k::tangents(x, s);
    const auto g = membrane_k::ref_metric(membrane_k::tangents(xr, s));
    const auto f = membrane_k::frame(t);
    const auto inv = membrane_k::invariants(t, f.J, g);
    EXPECT_NEAR(inv.A1, std::log(l1 * l2), 1e-14);
    EXPECT_NEAR(inv.A2, 0.5 * (l1 * l1 + l2 * l2) - 1, 1e-14);
    const Mat3 tau =
        membrane_k::tension(law(inv.A1, inv.A2), g.J / f.J, membrane_k::left_cauchy_green(t, g), f.n).full();
    const double J = l1 * l2;
    EXPECT_NEAR(tau(0, 0), Es / 3 * (l1 * l1 - 1 / (J * J)) / J, 1e-14);
    EXPECT_NEAR(tau(1, 1), Es / 3 * (l2 * l2 - 1 / (J * J)) / J, 1e-14);
    EXPECT_NEAR(tau(0, 1), 0, 1e-14);
    EXPECT_NEAR(tau(2, 2), 0, 1e-14);
  }
}

// Eq. (40) with the exact sphere normals n_i = X_i / R at the nodes: the interpolated normal is X(xi)/R, so
// kappa = P/R exactly at every point of the element (P the element's tangent projector).
TEST(MembraneKinematics, CurvatureOfSpherePatchIsProjectorOverRadius) {
  const double R = 0.7;
  const Nodes x = sphere_patch(R);
  for (const auto& p : tri6::kNodePoints) {
    const tri6::Shape s = tri6::shape(p.xi, p.eta);
    const auto f = membrane_k::frame(membrane_k::tangents(x, s));
    Vec3 dn_dxi, dn_deta;
    for (int j = 0; j < 6; ++j) {
      dn_dxi += s.dxi[j] * x[j] / R;
      dn_deta += s.deta[j] * x[j] / R;
    }
    const Mat3 kappa = membrane_k::curvature(f, dn_dxi, dn_deta);
    EXPECT_LT(max_diff(kappa, (1 / R) * (Mat3::identity() - Mat3::outer(f.n, f.n))), 1e-13);
    EXPECT_NEAR(0.5 * trace(kappa), 1 / R, 1e-13);  // mean curvature convention kappa_m = tr(kappa)/2
  }
}

// dW/da_alpha of the kernel against central differences of W(A1(a), A2(a)) in every component of a_xi, a_eta.
TEST(MembraneKinematics, EnergyGradientKernelMatchesFiniteDifferences) {
  const Nodes xr = sphere_patch(1.0);
  const Nodes x = map(xr, Mat3::from_rows({1.1, 0.2, 0}, {-0.1, 0.95, 0.15}, {0.05, 0, 1.2}), {});
  const Skalak law{0.4, 3.0};
  const tri6::Shape s = tri6::shape(0.3, 0.2);
  const auto g = membrane_k::ref_metric(membrane_k::tangents(xr, s));
  auto W = [&](const membrane_k::Tangents& t) {
    const auto inv = membrane_k::invariants(t, membrane_k::frame(t).J, g);
    return law(inv.A1, inv.A2).W;
  };
  const auto t = membrane_k::tangents(x, s);
  const auto f = membrane_k::frame(t);
  const auto inv = membrane_k::invariants(t, f.J, g);
  const auto dW = membrane_k::energy_gradient(law(inv.A1, inv.A2), t, f, g);
  const double h = 1e-6;
  for (int c = 0; c < 3; ++c) {
    auto tp = t, tm = t;
    tp.a_xi[c] += h;
    tm.a_xi[c] -= h;
    EXPECT_NEAR(dW.d_xi[c], (W(tp) - W(tm)) / (2 * h), 1e-8);
    tp = t, tm = t;
    tp.a_eta[c] += h;
    tm.a_eta[c] -= h;
    EXPECT_NEAR(dW.d_eta[c], (W(tp) - W(tm)) / (2 * h), 1e-8);
  }
}

// The quadrature rule integrates the quadratic shape functions exactly: 0 at vertices, 1/6 (= S/3) at
// mid-side nodes on the reference triangle of area 1/2; the reason vertices need another area weight.
TEST(MembraneKinematics, ShapeFunctionIntegralsVanishAtVertices) {
  std::array<double, 6> I{};
  for (const auto& q : tri6::kQuad) {
    const auto s = tri6::shape(q.xi, q.eta);
    for (int i = 0; i < 6; ++i) I[i] += q.w * s.N[i];
  }
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(I[i], 0, 1e-16);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(I[i], 1.0 / 6, 1e-16);
}
