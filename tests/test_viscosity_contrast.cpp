// Variable viscosity (docs/viscosity-contrast.md): the stress kernel against the Laplacian, manufactured flows with a
// smooth viscosity at second order in space and time (periodic, and with the viscosity varying at no-slip walls), and
// the interior indicator of a sphere.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/ViscosityIndicator.hpp"
#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/ViscousStress_K.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/verify/Convergence.hpp"

using namespace immerse;
using immerse::verify::min_observed_order;
using immerse::verify::observed_order;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double pi = std::numbers::pi;

// ABC flow S (a Beltrami field: (S·∇)S = ∇|S|²/2, ∇²S = −S, D S = 0) with T(t) = cos t, p = −ρ T²|S|²/2, and
// μ = μ0 (1 + χ), χ = 0.5 sin x sin y sin z; the force F = ρ T' S − T ∇·(μ (∇S + ∇Sᵀ)) makes it exact.
struct VariableViscosityMms {
  double rho = 1, mu0 = 1, A = 1, B = 0.8, C = 0.6, amp = 0.5;
  Vec3 shape(const Vec3& x) const {
    return {A * std::sin(x[2]) + C * std::cos(x[1]), B * std::sin(x[0]) + A * std::cos(x[2]),
            C * std::sin(x[1]) + B * std::cos(x[0])};
  }
  double chi(const Vec3& x) const { return amp * std::sin(x[0]) * std::sin(x[1]) * std::sin(x[2]); }
  Vec3 velocity(const Vec3& x, double t) const { return std::cos(t) * shape(x); }
  double pressure(const Vec3& x, double t) const {
    const Vec3 s = shape(x);
    return -0.5 * rho * std::cos(t) * std::cos(t) * dot(s, s);
  }
  // ∇·(μ (∇S + ∇Sᵀ)) = μ ∇²S + (∇S + ∇Sᵀ) ∇μ.
  Vec3 stress(const Vec3& x) const {
    const double mu = mu0 * (1 + chi(x));
    const Vec3 gmu = amp * mu0 *
                     Vec3{std::cos(x[0]) * std::sin(x[1]) * std::sin(x[2]), std::sin(x[0]) * std::cos(x[1]) * std::sin(x[2]),
                          std::sin(x[0]) * std::sin(x[1]) * std::cos(x[2])};
    const double e12 = -C * std::sin(x[1]) + B * std::cos(x[0]);
    const double e13 = A * std::cos(x[2]) - B * std::sin(x[0]);
    const double e23 = -A * std::sin(x[2]) + C * std::cos(x[1]);
    const Vec3 s = shape(x);
    return -mu * s + Vec3{e12 * gmu[1] + e13 * gmu[2], e12 * gmu[0] + e23 * gmu[2], e13 * gmu[0] + e23 * gmu[1]};
  }
};


/// The state after two steps of dt taken exactly from the manufactured flow `mms` (velocity(x, t), pressure(x, t)):
/// u^0, p^{-1/2}, and the history u^{-1} (the extrapolation of the viscous remainder), p^{-3/2} and
/// (u·∇_h u)^{-1}, so that every step is the scheme's second-order one (a start-up step is first order locally).
template <class Mms>
FluidState exact_start(const NavierStokesSolver& ns, const Mms& mms, double dt) {
  const Grid& grid = ns.grid();
  FluidState a = ns.initial_state();
  sample_velocity(grid, [&](const Vec3& x) { return mms.velocity(x, 0.0); }, a.u);
  ns.apply_wall_values(a.u);
  sample_pressure(grid, [&](const Vec3& x) { return mms.pressure(x, -0.5 * dt); }, a.p);
  a.u_prev = FaceField(grid);
  sample_velocity(grid, [&](const Vec3& x) { return mms.velocity(x, -dt); }, a.u_prev);
  ns.apply_wall_values(a.u_prev);
  sample_pressure(grid, [&](const Vec3& x) { return mms.pressure(x, -1.5 * dt); }, a.p_prev);
  const MacStencilGrid g(grid, ns.params());
  for (int d = 0; d < 3; ++d)
    for_each_face(g, d, [&](int i, int j, int k) {
      const mac::Index q{i, j, k};
      a.adv[d](i, j, k) = mac::advection_face(a.u_prev, g, d, q, mac::gather(a.u_prev[d], g, d, q));
    });
  a.dt_prev = a.dt_prev2 = dt;
  a.step = 2;
  return a;
}

/// The state after `steps` steps of dt from the exact u(0), p(−Δt/2), and (into p_before_last) p one step before.
FluidState integrate(const VariableViscosityMms& mms, int n, double dt, int steps, Array3* p_before_last = nullptr) {
  const Grid grid({n, n, n}, {2 * pi, 2 * pi, 2 * pi}, {P, P, P});
  FluidParams prm;
  prm.rho = mms.rho;
  prm.mu = mms.mu0;
  prm.pressure = PressurePredictor::Extrapolated;
  prm.variable_viscosity = true;
  prm.implicit_ratio = 1.5;  // max μ / μ0
  NavierStokesSolver ns(grid, prm, FftPlanning::Estimate);
  FluidState a = exact_start(ns, mms, dt), b;
  Array3 chi(n, n, n);
  sample_pressure(grid, [&](const Vec3& x) { return mms.chi(x); }, chi);
  FaceField shape(grid), stress(grid), force(grid);
  sample_velocity(grid, [&](const Vec3& x) { return mms.shape(x); }, shape);
  sample_velocity(grid, [&](const Vec3& x) { return mms.stress(x); }, stress);
  for (int s = 0; s < steps; ++s) {
    const double t = a.time + 0.5 * dt;
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < force[d].size(); ++i)
        force[d][i] = -mms.rho * std::sin(t) * shape[d][i] - std::cos(t) * stress[d][i];
    ns.step(a, force, dt, b, &chi);
    if (p_before_last && s == steps - 1) *p_before_last = a.p;
    std::swap(a, b);
  }
  return a;
}

/// χ = exp(1 − 1/(1 − s²)), s = |x − c|/R < 1 with R = 0.2, zero beyond: smooth, and zero within 0.3 of the walls of
/// the unit box (three cells from N = 10 on).
double bump(const Vec3& x) {
  const double s2 = dot(x - Vec3{0.5, 0.5, 0.5}, x - Vec3{0.5, 0.5, 0.5}) / (0.2 * 0.2);
  return s2 < 1 ? std::exp(1 - 1 / (1 - s2)) : 0.0;
}

/// ∇·(χ (∇S + ∇Sᵀ)) of the closed box's spatial velocity S by central differences of the exact S (steps 1e-4 and
/// 1e-5: errors near 1e-8, far below the grid's); zero where χ vanishes around x.
Vec3 bump_stress(const ClosedBoxMms& m, const Vec3& x) {
  if (dot(x - Vec3{0.5, 0.5, 0.5}, x - Vec3{0.5, 0.5, 0.5}) > 0.201 * 0.201) return {};
  const double d1 = 1e-4, d2 = 1e-5;
  const auto strain = [&](const Vec3& y, int i, int j) {
    Vec3 ej{}, ei{};
    ej[j] = d2;
    ei[i] = d2;
    return (m.velocity(y + ej, 0)[i] - m.velocity(y - ej, 0)[i] + m.velocity(y + ei, 0)[j] - m.velocity(y - ei, 0)[j]) /
           (2 * d2);
  };
  Vec3 v;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Vec3 e{};
      e[j] = d1;
      v[i] += (bump(x + e) * strain(x + e, i, j) - bump(x - e) * strain(x - e, i, j)) / (2 * d1);
    }
  return v;
}

/// The closed box (six no-slip walls) with μ = μ0 (1 + χ), χ the bump: the max error of u and the L2 error of p
/// after T = 0.25 with Δt = 0.2 h, from the exact u(0), p(−Δt/2) and history.
std::pair<double, double> closed_box_errors(int n) {
  const ClosedBoxMms mms{1.0, 0.1};
  const Grid grid({n, n, n}, {1.0, 1.0, 1.0}, {W, W, W});
  FluidParams prm;
  prm.mu = mms.mu;
  prm.pressure = PressurePredictor::Extrapolated;
  prm.variable_viscosity = true;
  prm.implicit_ratio = 2.0;
  NavierStokesSolver ns(grid, prm, FftPlanning::Estimate);
  const double T = 0.25;
  const int steps = static_cast<int>(std::ceil(T / (0.2 * grid.h())));
  const double dt = T / steps;
  FluidState a = exact_start(ns, mms, dt), b;
  Array3 chi(n, n, n);
  sample_pressure(grid, bump, chi);
  std::array<FaceField, 5> parts;
  for (auto& f : parts) f = FaceField(grid);
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k < parts[0][d].nz(); ++k)
      for (int j = 0; j < parts[0][d].ny(); ++j)
        for (int i = 0; i < parts[0][d].nx(); ++i) {
          const Vec3 x = grid.face_position(d, i, j, k);
          const auto v = mms.force_parts(x);
          for (int m = 0; m < 4; ++m) parts[m][d](i, j, k) = v[m][d];
          parts[4][d](i, j, k) = mms.mu * bump_stress(mms, x)[d];
        }
  FaceField force(grid);
  for (int s = 0; s < steps; ++s) {
    const double t = a.time + 0.5 * dt;
    const auto c = mms.force_coefficients(t);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < force[d].size(); ++i) {
        double v = 0;
        for (int m = 0; m < 4; ++m) v += c[m] * parts[m][d][i];
        force[d][i] = v - std::cos(t) * parts[4][d][i];
      }
    ns.step(a, force, dt, b, &chi);
    std::swap(a, b);
  }
  return {velocity_error(grid, a.u, [&](const Vec3& x) { return mms.velocity(x, T); }).max,
          pressure_error(grid, a.p, [&](const Vec3& x) { return mms.pressure(x, T - 0.5 * dt); }).l2};
}

/// χ = 0.5 cos(k_x x − 0.4) cos(k_y y − 1.1) cos(k_z z − 0.7) and its gradient: varying along the walls of the unit
/// box, with a non-zero normal derivative on them.
struct WallChi {
  Vec3 k{2, 2, 2};
  double operator()(const Vec3& x) const {
    return 0.5 * std::cos(k[0] * x[0] - 0.4) * std::cos(k[1] * x[1] - 1.1) * std::cos(k[2] * x[2] - 0.7);
  }
  Vec3 gradient(const Vec3& x) const {
    const double c0 = std::cos(k[0] * x[0] - 0.4), c1 = std::cos(k[1] * x[1] - 1.1), c2 = std::cos(k[2] * x[2] - 0.7);
    return -0.5 * Vec3{k[0] * std::sin(k[0] * x[0] - 0.4) * c1 * c2, k[1] * c0 * std::sin(k[1] * x[1] - 1.1) * c2,
                       k[2] * c0 * c1 * std::sin(k[2] * x[2] - 0.7)};
  }
};

/// A channel flow, walls x = 0, 1 and z = 0, 1, periodic in y (period 1): u = cos t S, p = cos t Π with
/// S = ∇×(ψ e_y) = (−∂_z ψ, 0, ∂_x ψ), ψ = a(x) a(z) b(y), a = sin²(πx), b = 1 + 0.5 cos 2πy (no slip: S and ∇S
/// vanish on the walls), Π = cos πx sin 2πy cos πz.
struct ChannelMms {
  double rho = 1, mu = 0.1;
  // k-th derivatives of a and b.
  static double a(int k, double x) {
    return k == 0 ? 0.5 * (1 - std::cos(2 * pi * x)) : -0.5 * std::pow(2 * pi, k) * std::cos(2 * pi * x + k * pi / 2);
  }
  static double b(int k, double y) { return (k == 0 ? 1.0 : 0.0) + 0.5 * std::pow(2 * pi, k) * std::cos(2 * pi * y + k * pi / 2); }
  /// ∂^o S_d, o the derivative order along each axis.
  static double spatial(int d, const Vec3& x, const std::array<int, 3>& o) {
    if (d == 0) return -a(o[0], x[0]) * b(o[1], x[1]) * a(o[2] + 1, x[2]);
    if (d == 2) return a(o[0] + 1, x[0]) * b(o[1], x[1]) * a(o[2], x[2]);
    return 0.0;
  }
  Vec3 shape(const Vec3& x) const { return {spatial(0, x, {}), 0.0, spatial(2, x, {})}; }
  /// ∂_j S_i.
  double gradient(const Vec3& x, int i, int j) const {
    std::array<int, 3> o{};
    o[j] = 1;
    return spatial(i, x, o);
  }
  Vec3 laplacian(const Vec3& x) const {
    Vec3 v;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        std::array<int, 3> o{};
        o[j] = 2;
        v[i] += spatial(i, x, o);
      }
    return v;
  }
  double pi_field(const Vec3& x) const {
    return std::cos(pi * x[0]) * std::sin(2 * pi * x[1]) * std::cos(pi * x[2]);
  }
  Vec3 pi_gradient(const Vec3& x) const {
    return {-pi * std::sin(pi * x[0]) * std::sin(2 * pi * x[1]) * std::cos(pi * x[2]),
            2 * pi * std::cos(pi * x[0]) * std::cos(2 * pi * x[1]) * std::cos(pi * x[2]),
            -pi * std::cos(pi * x[0]) * std::sin(2 * pi * x[1]) * std::sin(pi * x[2])};
  }
  Vec3 velocity(const Vec3& x, double t) const { return std::cos(t) * shape(x); }
  double pressure(const Vec3& x, double t) const { return std::cos(t) * pi_field(x); }
};

/// The spatial parts of the force of u = cos t S, p = cos t Π under μ = μ0 (1 + χ):
/// F = ρ T' S + ρ T² (S·∇)S + T ∇Π − μ0 T [(1 + χ) ∇²S + (∇S + ∇Sᵀ) ∇χ], T = cos t (D S = 0), from S, ∇S (grad(x, i, j)
/// = ∂_j S_i), ∇²S and ∇Π; the coefficients are those of ClosedBoxMms::force_coefficients.
template <class Grad>
std::array<Vec3, 4> wall_force_parts(const Vec3& S, const Grad& grad, const Vec3& lap, const Vec3& grad_pi,
                                     double chi, const Vec3& grad_chi) {
  Vec3 adv, stress = (1 + chi) * lap;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      adv[i] += S[j] * grad(i, j);
      stress[i] += (grad(i, j) + grad(j, i)) * grad_chi[j];
    }
  return {S, adv, grad_pi, stress};
}

/// The max error of u and the L2 error of p after T = 0.1 with Δt = 0.2 h, from the exact u(0), p(−Δt/2) and
/// history, of the flow `mms` on `grid` under μ = μ0 (1 + χ), the force from parts(x) (wall_force_parts).
template <class Mms, class Parts>
std::pair<double, double> wall_viscosity_errors(const Mms& mms, const Grid& grid, const WallChi& chi_of,
                                                const Parts& parts_of) {
  FluidParams prm;
  prm.rho = mms.rho;
  prm.mu = mms.mu;
  prm.pressure = PressurePredictor::Extrapolated;
  prm.variable_viscosity = true;
  prm.implicit_ratio = 1.5;  // max μ / μ0
  NavierStokesSolver ns(grid, prm, FftPlanning::Estimate);
  const double T = 0.1;
  const int steps = static_cast<int>(std::ceil(T / (0.2 * grid.h())));
  const double dt = T / steps;
  FluidState a = exact_start(ns, mms, dt), b;
  Array3 chi(grid.n(0), grid.n(1), grid.n(2));
  sample_pressure(grid, [&](const Vec3& x) { return chi_of(x); }, chi);
  std::array<FaceField, 4> parts;
  for (auto& f : parts) f = FaceField(grid);
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k < parts[0][d].nz(); ++k)
      for (int j = 0; j < parts[0][d].ny(); ++j)
        for (int i = 0; i < parts[0][d].nx(); ++i) {
          const auto v = parts_of(grid.face_position(d, i, j, k));
          for (int m = 0; m < 4; ++m) parts[m][d](i, j, k) = v[m][d];
        }
  FaceField force(grid);
  for (int s = 0; s < steps; ++s) {
    const double t = a.time + 0.5 * dt;
    const double c[4] = {-mms.rho * std::sin(t), mms.rho * std::cos(t) * std::cos(t), std::cos(t), -mms.mu * std::cos(t)};
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < force[d].size(); ++i) {
        double v = 0;
        for (int m = 0; m < 4; ++m) v += c[m] * parts[m][d][i];
        force[d][i] = v;
      }
    ns.step(a, force, dt, b, &chi);
    std::swap(a, b);
  }
  return {velocity_error(grid, a.u, [&](const Vec3& x) { return mms.velocity(x, T); }).max,
          pressure_error(grid, a.p, [&](const Vec3& x) { return mms.pressure(x, T - 0.5 * dt); }).l2};
}

/// The closed box's flow (ClosedBoxMms) under μ = μ0 (1 + χ), χ = WallChi.
std::pair<double, double> closed_box_wall_errors(int n) {
  const ClosedBoxMms mms{1.0, 0.1};
  const WallChi chi;
  const auto parts = [&](const Vec3& x) {
    const auto p = mms.force_parts(x);
    const auto grad = [&](int i, int j) { return mms.gradient(x, i, j); };
    return wall_force_parts(p[0], grad, p[3], p[2], chi(x), chi.gradient(x));
  };
  return wall_viscosity_errors(mms, Grid({n, n, n}, {1.0, 1.0, 1.0}, {W, W, W}), chi, parts);
}

/// The channel flow (ChannelMms) under μ = μ0 (1 + χ), χ = WallChi periodic in y.
std::pair<double, double> channel_wall_errors(int n) {
  const ChannelMms mms;
  const WallChi chi{{2, 2 * pi, 2}};
  const auto parts = [&](const Vec3& x) {
    const auto grad = [&](int i, int j) { return mms.gradient(x, i, j); };
    return wall_force_parts(mms.shape(x), grad, mms.laplacian(x), mms.pi_gradient(x), chi(x), chi.gradient(x));
  };
  return wall_viscosity_errors(mms, Grid({n, n, n}, {1.0, 1.0, 1.0}, {W, P, W}), chi, parts);
}

/// The observed orders (u max norm, p L2) of errors(n) over N = 10, 20, 40.
template <class Errors>
std::pair<double, double> wall_orders(const char* name, const Errors& errors) {
  std::vector<double> eu, ep;
  for (int n : {10, 20, 40}) {
    const auto [u, p] = errors(n);
    eu.push_back(u);
    ep.push_back(p);
  }
  const double order_u = min_observed_order(eu), order_p = min_observed_order(ep);
  std::printf("%s: errors u (max) %.3e %.3e %.3e (order %.3f), p (L2) %.3e %.3e %.3e (order %.3f)\n", name, eu[0],
              eu[1], eu[2], order_u, ep[0], ep[1], ep[2], order_p);
  return {order_u, order_p};
}

}  // namespace

TEST(ViscosityContrast, ManufacturedFlowInAClosedBoxIsSecondOrderInSpace) {
  // Six no-slip walls, the viscosity doubled in a smooth bump at the centre: the implicit viscosity μ_p = 2 μ0 then
  // differs from μ0 at the walls, where the remainder's Laplacian takes the homogeneous wall values.
  std::vector<double> eu, ep;
  for (int n : {10, 20, 40}) {
    const auto [u, p] = closed_box_errors(n);
    eu.push_back(u);
    ep.push_back(p);
  }
  const double order_u = min_observed_order(eu), order_p = min_observed_order(ep);
  std::printf("closed box: errors u (max) %.3e %.3e %.3e (order %.3f), p (L2) %.3e %.3e %.3e (order %.3f)\n", eu[0], eu[1],
              eu[2], order_u, ep[0], ep[1], ep[2], order_p);
  RecordProperty("order_u", std::to_string(order_u));
  RecordProperty("order_p", std::to_string(order_p));
  EXPECT_GE(order_u, 1.9);
  EXPECT_GE(order_p, 1.9);
}

TEST(ViscosityContrast, ManufacturedFlowWithTheViscosityVaryingAtTheWallsIsSecondOrderInSpace) {
  // μ = μ0 (1 + χ) varies along the walls and across them (χ = WallChi), in the closed box (six no-slip walls, the
  // closed_box_mms velocity) and in a channel (walls in x and z, periodic in y): the stress term reaches the walls.
  const auto [box_u, box_p] = wall_orders("closed box, viscosity at the walls", closed_box_wall_errors);
  const auto [channel_u, channel_p] = wall_orders("channel, viscosity at the walls", channel_wall_errors);
  RecordProperty("box_order_u", std::to_string(box_u));
  RecordProperty("box_order_p", std::to_string(box_p));
  RecordProperty("channel_order_u", std::to_string(channel_u));
  RecordProperty("channel_order_p", std::to_string(channel_p));
  EXPECT_GE(box_u, 1.8);
  EXPECT_GE(box_p, 1.8);
  EXPECT_GE(channel_u, 1.8);
  EXPECT_GE(channel_p, 1.8);
}

TEST(ViscosityContrast, StressOfConstantViscosityIsTheLaplacian) {
  // χ constant: ∇_h·(χ(∇_h u + ∇_h uᵀ)) = χ (∇_h² u + G D u) for any u, on every face of a periodic grid and of a
  // channel whose walls move (the ghost values of the Laplacian; the wall faces hold the normal wall velocity, zero).
  for (const Boundary wall : {P, W}) {
    const Grid grid({6, 5, 7}, {6.0, 5.0, 7.0}, {wall, P, wall});
    MacStencilGrid g(grid);
    if (wall == W) {
      g.wall_lower[0] = {0, 0.3, -0.2};
      g.wall_upper[0] = {0, -0.5, 0.4};
      g.wall_lower[2] = {0.7, 0.1, 0};
      g.wall_upper[2] = {-0.6, 0.2, 0};
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1, 1);
    FaceField u(grid);
    for (int d = 0; d < 3; ++d)
      for (double& v : u[d].values()) v = U(rng);
    if (wall == W)
      for (int j = 0; j < 5; ++j) {
        for (int k = 0; k < 7; ++k) u[0](0, j, k) = u[0](6, j, k) = 0.0;
        for (int i = 0; i < 6; ++i) u[2](i, j, 0) = u[2](i, j, 7) = 0.0;
      }
    Array3 chi(6, 5, 7), div(6, 5, 7);
    chi.fill(0.7);
    for_each_cell(g, [&](int i, int j, int k) { div(i, j, k) = mac::divergence_cell(u, g, {i, j, k}); });
    double worst = 0;
    for (int d = 0; d < 3; ++d)
      for_each_face(g, d, [&](int i, int j, int k) {
        const mac::Index q{i, j, k};
        const double expected = 0.7 * (mac::laplacian_face(u[d], g, d, q) + mac::gradient_face(div, g, d, q));
#pragma omp critical
        worst = std::max(worst, std::abs(mac::stress_divergence(u, chi, g, d, q) - expected));
      });
    EXPECT_LT(worst, 1e-12) << (wall == W ? "channel" : "periodic");
  }
}

TEST(ViscosityContrast, ManufacturedFlowIsSecondOrderInSpaceAndTime) {
  const VariableViscosityMms mms;
  const double T = 1.0;
  // Space: Δt = T/N ∝ h, N = 8, 16, 32 (max norm of u, L2 norm of p).
  std::vector<double> eu, ep;
  for (int n : {8, 16, 32}) {
    const Grid grid({n, n, n}, {2 * pi, 2 * pi, 2 * pi}, {P, P, P});
    const int steps = n;
    const FluidState s = integrate(mms, n, T / steps, steps);
    eu.push_back(velocity_error(grid, s.u, [&](const Vec3& x) { return mms.velocity(x, T); }).max);
    ep.push_back(pressure_error(grid, s.p, [&](const Vec3& x) { return mms.pressure(x, T - 0.5 * T / steps); }).l2);
  }
  const double space_u = min_observed_order(eu), space_p = min_observed_order(ep);
  // Time: N = 16, 4 x 3^k steps, differences of successive runs.
  std::vector<FluidState> runs;
  std::vector<Array3> before(3);
  for (int m = 1, r = 0; m <= 9; m *= 3, ++r) runs.push_back(integrate(mms, 16, T / (4 * m), 4 * m, &before[r]));
  const Grid g16({16, 16, 16}, {2 * pi, 2 * pi, 2 * pi}, {P, P, P});
  const double d0 = velocity_difference(g16, runs[0].u, runs[1].u).max;
  const double d1 = velocity_difference(g16, runs[1].u, runs[2].u).max;
  const double time_u = observed_order(d0, d1, 3.0);
  // p of a run is at T − Δt/2: the finer run's pressure one step before its end is at that time.
  const double time_p = observed_order(pressure_difference(runs[0].p, before[1]).max,
                                       pressure_difference(runs[1].p, before[2]).max, 3.0);
  std::printf("space order u %.3f p %.3f, time order u %.3f p %.3f\n", space_u, space_p, time_u, time_p);
  RecordProperty("space_order_u", std::to_string(space_u));
  RecordProperty("space_order_p", std::to_string(space_p));
  RecordProperty("time_order_u", std::to_string(time_u));
  RecordProperty("time_order_p", std::to_string(time_p));
  EXPECT_GE(space_u, 1.9);
  EXPECT_GE(space_p, 1.9);
  EXPECT_GE(time_u, 1.9);
  EXPECT_GE(time_p, 1.9);
}

/// The largest and the last kinetic energy Σ u² of `steps` unforced steps of a random divergence-free flow under a
/// random (cell by cell) χ in [0, contrast − 1], relative to the energy after the first step (which projects it).
std::pair<double, double> energy_history(double implicit_ratio, double contrast, int steps, double nu_dt_h2) {
  const int n = 12;
  const Grid grid({n, n, n}, {1.0, 1.0, 1.0}, {P, P, W});
  FluidParams prm;
  prm.variable_viscosity = true;
  prm.implicit_ratio = implicit_ratio;
  NavierStokesSolver ns(grid, prm, FftPlanning::Estimate);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1), C(0, contrast - 1);
  FluidState a = ns.initial_state(), b;
  for (int d = 0; d < 3; ++d)
    for (double& v : a.u[d].values()) v = U(rng);
  ns.apply_wall_values(a.u);
  Array3 chi(n, n, n);
  for (int k = 0; k < n; ++k)  // up to the walls
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) chi(i, j, k) = C(rng);
  const double dt = nu_dt_h2 * grid.h() * grid.h();
  const FaceField zero(grid);
  double first = 0, largest = 0, last = 0;
  for (int s = 0; s < steps; ++s) {
    ns.step(a, zero, dt, b, s == 0 ? nullptr : &chi);
    std::swap(a, b);
    last = 0;
    for (int d = 0; d < 3; ++d)
      for (double v : a.u[d].values()) last += v * v;
    if (s == 0) first = last;
    largest = std::max(largest, last);
  }
  return {largest / first, last / first};
}

TEST(ViscosityContrast, UnforcedFlowDecaysInTheStokesLimitWhenTheImplicitViscosityIsTheLargest) {
  // A viscosity varying by 10 from cell to cell, ν Δt/h² = 100 and 0.5: with the implicit viscosity the largest
  // one the extrapolated remainder is stable (the energy never exceeds that of the projected initial flow and decays
  // by orders of magnitude); at a fourth of it the same flow grows without bound.
  for (const double nu_dt_h2 : {100.0, 0.5}) {
    const auto [largest, last] = energy_history(10.0, 10.0, 60, nu_dt_h2);
    std::printf("nu dt/h^2 = %g: largest energy %.3f, last %.3e\n", nu_dt_h2, largest, last);
    EXPECT_LE(largest, 1.0);
    EXPECT_LT(last, 1e-2);
  }
  EXPECT_FALSE(energy_history(2.5, 10.0, 60, 100.0).second < 1e3);  // (it overflows)
}

TEST(ViscosityContrast, IndicatorOfASphereIsTheContrastInsideAndZeroOutside) {
  // In the middle of the box, and 1.2 cells from the wall z = 0 (the delta function reaches the wall faces).
  const Grid grid({24, 24, 24}, {3.0, 3.0, 3.0}, {P, P, W});
  IBCoupler coupler(grid);
  ViscosityIndicator indicator(coupler);
  const Mesh mesh = icosahedral_sphere(3);
  for (const Vec3& c : {Vec3{1.5, 1.45, 1.55}, Vec3{1.5, 1.45, 0.8 + 1.2 * grid.h()}}) {
    std::vector<Vec3> X;
    for (const Vec3& p : mesh.nodes) X.push_back(c + 0.8 * p);
    const double V = volume(mesh, X);
    for (const double lambda : {5.0, 0.2}) {
      Array3 chi;
      const IndicatorSurface s{&mesh.elements, &X, lambda};
      indicator.compute({&s, 1}, chi);
      const double h = grid.h(), w = lambda - 1;
      double integral = 0, inside = 0, outside = 0;
      for (int k = 0; k < 24; ++k)
        for (int j = 0; j < 24; ++j)
          for (int i = 0; i < 24; ++i) {
            integral += chi(i, j, k) * h * h * h;
            const double r = norm(grid.cell_position(i, j, k) - c);
            if (r < 0.8 - 2 * h) inside = std::max(inside, std::abs(chi(i, j, k) - w));
            if (r > 0.8 + 2 * h) outside = std::max(outside, std::abs(chi(i, j, k)));
          }
      std::printf("centre z %.4f, lambda %g: integral %.6f of %.6f, inside error %.3e, outside %.3e\n", c.z, lambda,
                  integral, w * V, inside, outside);
      EXPECT_NEAR(integral, w * V, 1e-2 * std::abs(w) * V);
      EXPECT_LT(inside, 2e-2 * std::abs(w));
      EXPECT_EQ(outside, 0.0);
      EXPECT_DOUBLE_EQ(indicator.target_integral(), w * V);
    }
  }
}
