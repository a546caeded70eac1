#pragma once
// Exact solutions of the incompressible Navier–Stokes equations (1)–(3) used to verify the fluid solver
// (formulas from docs/theory/conventions.md, "Exact flows used by the fluid studies"). ν = μ/ρ.
#include <array>

#include "immerse/core/Vec3.hpp"

namespace immerse {

/// Taylor–Green vortex in the x–y plane, extruded along z (periodic box of period 2π/k):
/// u = sin kx cos ky F, v = −cos kx sin ky F, w = 0, p = (ρ/4)(cos 2kx + cos 2ky) F², F = exp(−2νk²t).
struct TaylorGreen {
  double k = 1, rho = 1, mu = 1;
  Vec3 velocity(const Vec3& x, double t) const;
  double pressure(const Vec3& x, double t) const;
};

/// Arnold–Beltrami–Childress flow (periodic box of period 2π/k), a Beltrami field (∇×u = k u):
/// u = (A sin kz + C cos ky, B sin kx + A cos kz, C sin ky + B cos kx) e^{−νk²t}, p = −ρ|u|²/2.
struct AbcFlow {
  double A = 1, B = 1, C = 1, k = 1, rho = 1, mu = 1;
  Vec3 velocity(const Vec3& x, double t) const;
  double pressure(const Vec3& x, double t) const;
};

/// Start-up Couette flow between walls z = z_lower and z = z_upper moving tangentially with wall_lower and
/// wall_upper (x, y components), fluid at rest at t = 0: the linear profile minus its sine series
///   u(s, t) = u_l + (u_u − u_l) s/L + Σ_n b_n sin(nπs/L) exp(−ν (nπ/L)² t),  b_n = −2(u_l − (−1)^n u_u)/(nπ),
/// s = z − z_lower, L = z_upper − z_lower. No pressure gradient. Needs t > 0.
struct CouetteStartup {
  double z_lower = 0, z_upper = 1, rho = 1, mu = 1;
  Vec3 wall_lower{}, wall_upper{};
  Vec3 velocity(const Vec3& x, double t) const;
  Vec3 steady(const Vec3& x) const;
};

/// Steady pressure-driven flow along x in the duct |y| < a, |z| < b driven by G = −dp/dx (body force):
/// u = G/(2μ) (a² − y²) − (16 a² G/(μ π³)) Σ_{n odd} (−1)^{(n−1)/2} n⁻³ cosh(nπz/2a)/cosh(nπb/2a) cos(nπy/2a).
struct DuctPoiseuille {
  double a = 1, b = 1, G = 1, mu = 1;
  double velocity(double y, double z) const;
  /// Q = (4 b a³ G / 3μ) [1 − (192 a / π⁵ b) Σ_{n odd} tanh(nπb/2a)/n⁵].
  double flow_rate() const;
};

/// Manufactured solution in the closed unit box [0,1]³ with no-slip walls on all six faces: u = ∇×(χ e_x + ψ e_z)
/// T(t) with ψ = s(x)s(y)σ(z), χ = σ(x)s(y)s(z), s = sin²(πξ) (value and slope vanish on the walls),
/// σ = sin(πξ), T = cos t; so u = 0 on every wall and ∇·u = 0. Pressure p = cos t sin πx sin πy sin πz
/// (non-zero normal derivative on the walls). The force F = ρ(u_t + u·∇u) + ∇p − μΔu makes it exact.
struct ClosedBoxMms {
  double rho = 1, mu = 1;
  Vec3 velocity(const Vec3& x, double t) const;
  double pressure(const Vec3& x, double t) const;
  Vec3 force(const Vec3& x, double t) const;
  /// ∂_j S_i of the spatial factor S = u / T(t).
  double gradient(const Vec3& x, int i, int j) const;
  /// The force separates in time: with u = T(t) S(x), p = T(t) Π(x),
  /// F = ρ T' S + ρ T² (S·∇)S + T ∇Π − μ T ΔS = Σ_i c_i(t) part_i(x); so a grid can sample the parts once.
  std::array<Vec3, 4> force_parts(const Vec3& x) const;
  std::array<double, 4> force_coefficients(double t) const;
};

}  // namespace immerse
