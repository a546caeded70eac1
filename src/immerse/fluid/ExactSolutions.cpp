#include "immerse/fluid/ExactSolutions.hpp"

#include <cmath>
#include <numbers>

namespace immerse {

namespace {
constexpr double pi = std::numbers::pi;
}

Vec3 TaylorGreen::velocity(const Vec3& x, double t) const {
  const double F = std::exp(-2.0 * mu / rho * k * k * t);
  return {std::sin(k * x.x) * std::cos(k * x.y) * F, -std::cos(k * x.x) * std::sin(k * x.y) * F, 0.0};
}

double TaylorGreen::pressure(const Vec3& x, double t) const {
  const double F = std::exp(-2.0 * mu / rho * k * k * t);
  return 0.25 * rho * (std::cos(2 * k * x.x) + std::cos(2 * k * x.y)) * F * F;
}

Vec3 AbcFlow::velocity(const Vec3& x, double t) const {
  const double F = std::exp(-mu / rho * k * k * t);
  return Vec3{A * std::sin(k * x.z) + C * std::cos(k * x.y), B * std::sin(k * x.x) + A * std::cos(k * x.z),
              C * std::sin(k * x.y) + B * std::cos(k * x.x)} *
         F;
}

double AbcFlow::pressure(const Vec3& x, double t) const {
  const Vec3 u = velocity(x, t);
  return -0.5 * rho * dot(u, u);
}

Vec3 CouetteStartup::steady(const Vec3& x) const {
  const double s = (x.z - z_lower) / (z_upper - z_lower);
  return wall_lower + (wall_upper - wall_lower) * s;
}

Vec3 CouetteStartup::velocity(const Vec3& x, double t) const {
  const double L = z_upper - z_lower, s = x.z - z_lower, nu = mu / rho;
  Vec3 u = steady(x);
  for (int n = 1; n < 1000000; ++n) {
    const double kn = n * pi / L, decay = std::exp(-nu * kn * kn * t);
    if (decay * (norm(wall_lower) + norm(wall_upper)) < 1e-18) break;
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    for (int d = 0; d < 2; ++d)
      u[d] += -2.0 * (wall_lower[d] - sign * wall_upper[d]) / (n * pi) * std::sin(kn * s) * decay;
  }
  return u;
}

double DuctPoiseuille::velocity(double y, double z) const {
  double u = G / (2 * mu) * (a * a - y * y);
  const double az = std::abs(z);
  for (int n = 1; n < 2000001; n += 2) {
    const double q = n * pi / (2 * a);
    // cosh(q z)/cosh(q b) without overflow
    const double ratio = std::exp(q * (az - b)) * (1 + std::exp(-2 * q * az)) / (1 + std::exp(-2 * q * b));
    const double sign = ((n - 1) / 2) % 2 == 0 ? 1.0 : -1.0;
    const double term = 16 * a * a * G / (mu * pi * pi * pi) * sign / (double(n) * n * n) * ratio;
    u -= term * std::cos(q * y);
    if (std::abs(term) < 1e-18 * G * a * a / mu) break;
  }
  return u;
}

double DuctPoiseuille::flow_rate() const {
  double s = 0;
  for (int n = 1; n < 2001; n += 2) s += std::tanh(n * pi * b / (2 * a)) / std::pow(n, 5);
  return 4 * b * a * a * a * G / (3 * mu) * (1 - 192 * a / (std::pow(pi, 5) * b) * s);
}

namespace {

// 1D factors of the manufactured field and their derivatives of order k:
// s(ξ) = sin²(πξ) = (1 − cos 2πξ)/2 and σ(ξ) = sin(πξ).
double s_k(int k, double x) {
  if (k == 0) return std::pow(std::sin(pi * x), 2);
  return -0.5 * std::pow(2 * pi, k) * std::cos(2 * pi * x + k * pi / 2);
}
double sigma_k(int k, double x) { return std::pow(pi, k) * std::sin(pi * x + k * pi / 2); }

// One separable term c · f_x(x) f_y(y) f_z(z) with f = s or σ and a derivative order per axis.
struct Term {
  double c;
  bool sigma[3];
  int order[3];
  double eval(const Vec3& x, const int extra[3]) const {
    double v = c;
    for (int a = 0; a < 3; ++a) v *= sigma[a] ? sigma_k(order[a] + extra[a], x[a]) : s_k(order[a] + extra[a], x[a]);
    return v;
  }
};

// u = ∇×(χ e_x + ψ e_z):  u = ψ_y,  v = χ_z − ψ_x,  w = −χ_y.
const Term kTerms[3][2] = {
    {{1, {false, false, true}, {0, 1, 0}}, {0, {false, false, false}, {0, 0, 0}}},
    {{1, {true, false, false}, {0, 0, 1}}, {-1, {false, false, true}, {1, 0, 0}}},
    {{-1, {true, false, false}, {0, 1, 0}}, {0, {false, false, false}, {0, 0, 0}}},
};

// Spatial factor of component d with extra derivatives `extra`.
double spatial(int d, const Vec3& x, const int extra[3]) {
  return kTerms[d][0].eval(x, extra) + kTerms[d][1].eval(x, extra);
}

}  // namespace

Vec3 ClosedBoxMms::velocity(const Vec3& x, double t) const {
  const int none[3] = {0, 0, 0};
  return Vec3{spatial(0, x, none), spatial(1, x, none), spatial(2, x, none)} * std::cos(t);
}

double ClosedBoxMms::gradient(const Vec3& x, int i, int j) const {
  int first[3] = {0, 0, 0};
  first[j] = 1;
  return spatial(i, x, first);
}

double ClosedBoxMms::pressure(const Vec3& x, double t) const {
  return std::cos(t) * std::sin(pi * x.x) * std::sin(pi * x.y) * std::sin(pi * x.z);
}

std::array<Vec3, 4> ClosedBoxMms::force_parts(const Vec3& x) const {
  const int none[3] = {0, 0, 0};
  const Vec3 S{spatial(0, x, none), spatial(1, x, none), spatial(2, x, none)};
  Vec3 adv, lap;
  for (int d = 0; d < 3; ++d)
    for (int e = 0; e < 3; ++e) {
      int first[3] = {0, 0, 0}, second[3] = {0, 0, 0};
      first[e] = 1;
      second[e] = 2;
      adv[d] += S[e] * spatial(d, x, first);
      lap[d] += spatial(d, x, second);
    }
  const Vec3 grad_pi = Vec3{std::cos(pi * x.x) * std::sin(pi * x.y) * std::sin(pi * x.z),
                            std::sin(pi * x.x) * std::cos(pi * x.y) * std::sin(pi * x.z),
                            std::sin(pi * x.x) * std::sin(pi * x.y) * std::cos(pi * x.z)} *
                       pi;
  return {S, adv, grad_pi, lap};
}

std::array<double, 4> ClosedBoxMms::force_coefficients(double t) const {
  const double T = std::cos(t), dT = -std::sin(t);
  return {rho * dT, rho * T * T, T, -mu * T};
}

Vec3 ClosedBoxMms::force(const Vec3& x, double t) const {
  const auto parts = force_parts(x);
  const auto c = force_coefficients(t);
  Vec3 f;
  for (int i = 0; i < 4; ++i) f += c[i] * parts[i];
  return f;
}

}  // namespace immerse
