#pragma once
// Pointwise kinematics of a curved membrane element (paper §2.3, §3). Each function works on the tangent
// vectors a_xi = dX/dxi, a_eta = dX/deta at one parametric point; the element loops live in ElasticMembrane.
//
//   dual basis       a^xi = (a_eta x n)/J, a^eta = (n x a_xi)/J,  J = |a_xi x a_eta|,  n = a_xi x a_eta / J
//   eq. (39)         A . abar_xi = a_xi, A . abar_eta = a_eta, A . nbar = 0   =>   A = a_alpha (x) abar^alpha
//   eq. (17)         B = A A^T = Gbar^{alpha beta} a_alpha (x) a_beta,  Gbar^{alpha beta} = abar^alpha . abar^beta
//   eq. (19)         A1 = ln(lambda1 lambda2) = ln(J / Jbar)
//   eq. (20)         A2 = tr(B)/2 - 1
//   eq. (18)         tau = e^{-A1} (dW/dA1 P + dW/dA2 B),  P = I - n n
//   eq. (40)         a_xi . kappa = dn/dxi, a_eta . kappa = dn/deta, n . kappa = 0  =>  kappa = a^alpha (x) dn/dalpha
//   eqs. (41), (27)  K = a^alpha (x) dm/dalpha,  (P.grad).m = K_iik = a^alpha . dm/dalpha,  q = [(P.grad).m] . P
// Energy gradient at a quadrature point (ElasticMembrane, energy method):
//   dA1/da_alpha = a^alpha,  dA2/da_alpha = Gbar^{alpha beta} a_beta = A abar^alpha,
//   dW/da_alpha = dW/dA1 a^alpha + dW/dA2 Gbar^{alpha beta} a_beta.
// Verified by: the tests MembraneKinematics.* (eq. 39, planar-stretch invariants and tension, sphere-patch curvature,
// energy-gradient kernel against finite differences) and the study membrane_energy_gradient.
#include <array>
#include <cmath>

#include "immerse/core/Mat3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/EnergyDensity.hpp"
#include "immerse/membrane/QuadraticTriangle_K.hpp"

namespace immerse::membrane_k {

using Nodes = std::array<Vec3, tri6::kNodes>;

struct Tangents {
  Vec3 a_xi, a_eta;
};

/// a_alpha = sum_i x_i dN_i/dalpha (eq. 38 differentiated).
[[gnu::always_inline]] inline Tangents tangents(const Nodes& x, const tri6::Shape& s) {
  Tangents t;
  for (int i = 0; i < tri6::kNodes; ++i) {
    t.a_xi += s.dxi[i] * x[i];
    t.a_eta += s.deta[i] * x[i];
  }
  return t;
}

/// Unit normal, area Jacobian and dual (contravariant) tangent basis at a point.
struct Frame {
  Vec3 n;
  double J;
  Vec3 d_xi, d_eta;  ///< a^xi, a^eta: a^alpha . a_beta = delta, a^alpha . n = 0
};

[[gnu::always_inline]] inline Frame frame(const Tangents& t) {
  const Vec3 c = cross(t.a_xi, t.a_eta);
  const double J = norm(c), r = 1 / J;
  const Vec3 n = c * r;
  return {n, J, cross(t.a_eta, n) * r, cross(n, t.a_xi) * r};
}

/// Reference-configuration data a point needs: contravariant metric Gbar^{alpha beta} and Jacobian Jbar.
struct RefMetric {
  double g_xx, g_xe, g_ee, J;
};

[[gnu::always_inline]] inline RefMetric ref_metric(const Tangents& t) {
  const Frame f = frame(t);
  return {dot(f.d_xi, f.d_xi), dot(f.d_xi, f.d_eta), dot(f.d_eta, f.d_eta), f.J};
}

/// Eq. (39) solved in closed form: A = a_xi (x) abar^xi + a_eta (x) abar^eta.
inline Mat3 deformation_gradient(const Tangents& t, const Frame& ref) {
  return Mat3::outer(t.a_xi, ref.d_xi) + Mat3::outer(t.a_eta, ref.d_eta);
}

/// A symmetric 3x3 tensor by its six independent components (B, P and the tension tau are symmetric).
struct SymTensor {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  SymTensor& operator+=(const SymTensor& b) {
    xx += b.xx; xy += b.xy; xz += b.xz; yy += b.yy; yz += b.yz; zz += b.zz;
    return *this;
  }
  SymTensor& operator*=(double s) {
    xx *= s; xy *= s; xz *= s; yy *= s; yz *= s; zz *= s;
    return *this;
  }
  Mat3 full() const { return Mat3::from_rows({xx, xy, xz}, {xy, yy, yz}, {xz, yz, zz}); }
};

/// T v for a symmetric T.
inline Vec3 operator*(const SymTensor& t, const Vec3& v) {
  return {t.xx * v.x + t.xy * v.y + t.xz * v.z, t.xy * v.x + t.yy * v.y + t.yz * v.z,
          t.xz * v.x + t.yz * v.y + t.zz * v.z};
}

/// Left Cauchy-Green tensor B = A A^T (17) through the reference metric:
/// B = Gbar^{xx} a_xi a_xi + Gbar^{ee} a_eta a_eta + Gbar^{xe} (a_xi a_eta + a_eta a_xi) = u a_xi + v a_eta
/// with u = Gbar^{xx} a_xi + Gbar^{xe} a_eta, v = Gbar^{xe} a_xi + Gbar^{ee} a_eta (upper triangle stored).
[[gnu::always_inline]] inline SymTensor left_cauchy_green(const Tangents& t, const RefMetric& g) {
  const Vec3& a = t.a_xi;
  const Vec3& b = t.a_eta;
  const Vec3 u = g.g_xx * a + g.g_xe * b, v = g.g_xe * a + g.g_ee * b;
  return {u.x * a.x + v.x * b.x, u.x * a.y + v.x * b.y, u.x * a.z + v.x * b.z,
          u.y * a.y + v.y * b.y, u.y * a.z + v.y * b.z, u.z * a.z + v.z * b.z};
}

/// Strain invariants (19), (20) at a point with current Jacobian J.
struct Invariants {
  double A1, A2;
};

/// A2 (20) = tr(B)/2 - 1 = Gbar^{alpha beta} a_alpha . a_beta / 2 - 1.
[[gnu::always_inline]] inline double second_invariant(const Tangents& t, const RefMetric& g) {
  return 0.5 * (g.g_xx * dot(t.a_xi, t.a_xi) + 2 * g.g_xe * dot(t.a_xi, t.a_eta) + g.g_ee * dot(t.a_eta, t.a_eta)) -
         1;
}

[[gnu::always_inline]] inline Invariants invariants(const Tangents& t, double J, const RefMetric& g) {
  return {std::log(J / g.J), second_invariant(t, g)};
}

/// Half the difference of the squared principal stretches, (lambda1^2 - lambda2^2)/2, from the eigenvalues of
/// the 2x2 matrix M = Gbar^{-1} g (g_{alpha beta} = a_alpha . a_beta), computed without the cancellation of
/// sqrt((tr M / 2)^2 - det M) near isotropic states. With (20): lambda1,2^2 = A2 + 1 +- this.
inline double principal_half_difference(const Tangents& t, const RefMetric& g) {
  const double g11 = dot(t.a_xi, t.a_xi), g12 = dot(t.a_xi, t.a_eta), g22 = dot(t.a_eta, t.a_eta);
  const double m11 = g.g_xx * g11 + g.g_xe * g12, m12 = g.g_xx * g12 + g.g_xe * g22;
  const double m21 = g.g_xe * g11 + g.g_ee * g12, m22 = g.g_xe * g12 + g.g_ee * g22;
  return std::sqrt(std::fmax(0.0, 0.25 * (m11 - m22) * (m11 - m22) + m12 * m21));
}

/// Tension tensor (18), tau = e^{-A1} (dW/dA1 P + dW/dA2 B), with e^{-A1} = Jbar / J (19) given as `shrink`.
[[gnu::always_inline]] inline SymTensor tension(const EnergyDensity& w, double shrink, const SymTensor& B, const Vec3& n) {
  const double w1 = shrink * w.dW_dA1, w2 = shrink * w.dW_dA2;
  return {w1 * (1 - n.x * n.x) + w2 * B.xx, w2 * B.xy - w1 * (n.x * n.y), w2 * B.xz - w1 * (n.x * n.z),
          w1 * (1 - n.y * n.y) + w2 * B.yy, w2 * B.yz - w1 * (n.y * n.z), w1 * (1 - n.z * n.z) + w2 * B.zz};
}

/// Curvature tensor (40) from the parametric derivatives of the normal field.
[[gnu::always_inline]] inline Mat3 curvature(const Frame& f, const Vec3& dn_dxi, const Vec3& dn_deta) {
  return Mat3::outer(f.d_xi, dn_dxi) + Mat3::outer(f.d_eta, dn_deta);
}

/// Surface divergence of the moment tensor, (P.grad).m = tr K with K from (41).
[[gnu::always_inline]] inline Vec3 moment_divergence(const Frame& f, const Mat3& dm_dxi, const Mat3& dm_deta) {
  return f.d_xi * dm_dxi + f.d_eta * dm_deta;
}

/// Energy gradient dW/da_alpha at a point (see header).
struct EnergyGradient {
  Vec3 d_xi, d_eta;
};

[[gnu::always_inline]] inline EnergyGradient energy_gradient(const EnergyDensity& w, const Tangents& t, const Frame& f, const RefMetric& g) {
  return {w.dW_dA1 * f.d_xi + w.dW_dA2 * (g.g_xx * t.a_xi + g.g_xe * t.a_eta),
          w.dW_dA1 * f.d_eta + w.dW_dA2 * (g.g_xe * t.a_xi + g.g_ee * t.a_eta)};
}

}  // namespace immerse::membrane_k
