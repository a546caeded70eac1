// Verification studies of the MAC-grid Navier–Stokes solver (paper §2.1–2.2, eqs. 9–13).
//
// Spatial order: the same flow on grids h, h/2, h/4, ... with Δt ∝ h (the scheme is second order in both, so
// the error is O(h²)), errors against the exact solution; u at t = T, p at t = T − Δt/2 (p lives at half steps).
// Pressure errors are taken after removing the mean of each field.
// Time order: a fixed grid and Δt, Δt/3, Δt/9, measured by Richardson-type differences e(Δt) = ‖v(Δt) − v(Δt/3)‖
// on the same grid, so the spatial error cancels exactly and only the temporal error of the fully discrete
// scheme is measured (against the exact solution, the O(h²) spatial error would swamp the temporal error on any
// affordable grid). The refinement ratio is 3 (not 2) so that the half-step pressure times coincide: the last p
// of the Δt run (at T − Δt/2) is compared with the second-to-last p of the Δt/3 run (at T − Δt/3 − Δt/6).
// Every run starts from the exact u(0) and p(−Δt/2).
//
// couette: the spatial order is measured against the series solution (started from the series at t0 > 0);
// the steady state reached from rest is compared with the linear profile, which the discrete problem
// reproduces exactly.
// duct_poiseuille: the steady discrete solution (one direct transform solve of μ∇_h²u = −G) is compared with the
// series (spatial order of u and of the flow rate); then the state reached by time stepping from rest is compared
// with that discrete steady solution (the continuous one differs from it by O(h²)).
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/verify/Convergence.hpp"
#include "immerse/verify/Study.hpp"

namespace immerse::verify {

namespace {

using VelocityFn = std::function<Vec3(const Vec3&, double)>;
using PressureFn = std::function<double(const Vec3&, double)>;

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

std::string bc_name(const std::array<Boundary, 3>& bc) {
  std::string s;
  for (Boundary b : bc) s += b == P ? 'P' : 'W';
  return s;
}

/// Writes the force F(t) on the faces of a grid.
using ForceFn = std::function<void(double t, FaceField& f)>;

/// A flow with an exact solution: velocity, pressure and (optionally) the force that makes it exact, made for
/// a given grid.
struct ExactFlow {
  VelocityFn u;
  PressureFn p;
  std::function<ForceFn(const Grid&)> force;  // empty: no force
};

/// The exact velocity and pressure of an analytic solution (any type with velocity(x, t) and pressure(x, t)).
template <class Solution>
ExactFlow exact_flow(const Solution& sol, std::function<ForceFn(const Grid&)> force = {}) {
  return {[sol](const Vec3& x, double t) { return sol.velocity(x, t); },
          [sol](const Vec3& x, double t) { return sol.pressure(x, t); }, std::move(force)};
}

struct RunResult {
  FluidState last;
  Array3 p_before_last;  // p one step before the end
};

/// Starts from the exact u(0) and p(−Δt/2) and takes `steps` steps of Δt, with F^{n+1/2} sampled at t^{n+1/2}.
RunResult integrate(const Grid& grid, const FluidParams& params, const ExactFlow& flow, double dt, int steps) {
  NavierStokesSolver ns(grid, params, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  sample_velocity(
      grid, [&](const Vec3& x) { return flow.u(x, 0.0); }, a.u);
  ns.apply_wall_values(a.u);
  sample_pressure(
      grid, [&](const Vec3& x) { return flow.p(x, -0.5 * dt); }, a.p);
  FaceField force(grid);
  const ForceFn force_at = flow.force ? flow.force(grid) : ForceFn{};
  RunResult r;
  for (int n = 0; n < steps; ++n) {
    if (force_at) force_at(a.time + 0.5 * dt, force);
    ns.step(a, force, dt, b);
    if (n == steps - 1) r.p_before_last = a.p;
    std::swap(a, b);
  }
  r.last = std::move(a);
  return r;
}

/// Number of steps to reach time t from rest with a step that damps every grid mode: Crank–Nicolson multiplies
/// the stiffest mode by (1 − a)/(1 + a) per step, a = 2νΔt/h² per wall axis; a ≤ 50 keeps |factor| ≤ 0.96.
int steps_to_steady(double t, double dt_max, double h, double nu) {
  return static_cast<int>(std::ceil(t / std::fmin(dt_max, 25 * h * h / nu)));
}

struct FlowSetup {
  std::function<Grid(int)> grid;  // grid at resolution N
  FluidParams params;
  ExactFlow flow;
  double T;         // final time
  double dt_per_h;  // Δt = dt_per_h · h (spatial study)
};

void space_study(const FlowSetup& s, const std::vector<int>& ns, std::vector<Check>& checks) {
  std::vector<double> eu2, eum, ep2, epm;
  for (int n : ns) {
    const Grid g = s.grid(n);
    const int steps = static_cast<int>(std::ceil(s.T / (s.dt_per_h * g.h())));
    const double dt = s.T / steps;
    const RunResult r = integrate(g, s.params, s.flow, dt, steps);
    const auto eu = velocity_error(g, r.last.u, [&](const Vec3& x) { return s.flow.u(x, s.T); });
    const auto ep = pressure_error(g, r.last.p, [&](const Vec3& x) { return s.flow.p(x, s.T - 0.5 * dt); });
    eu2.push_back(eu.l2);
    eum.push_back(eu.max);
    ep2.push_back(ep.l2);
    epm.push_back(ep.max);
  }
  const std::string seq = " N=" + std::to_string(ns.front()) + ".." + std::to_string(ns.back());
  checks.push_back({"order of u (L2), space," + seq, min_observed_order(eu2), ">=", 1.9});
  checks.push_back({"order of u (max), space," + seq, min_observed_order(eum), ">=", 1.9});
  checks.push_back({"order of p (L2), space," + seq, min_observed_order(ep2), ">=", 1.9});
  checks.push_back({"order of p (max), space," + seq, min_observed_order(epm), ">=", 1.9});
  const Grid g = s.grid(ns.back());
  const double u_rms = velocity_error(g, FaceField(g), [&](const Vec3& x) { return s.flow.u(x, s.T); }).l2;
  checks.push_back({"relative L2 error of u, N=" + std::to_string(ns.back()), eu2.back() / u_rms, "<=", 1e-2});
}

void time_study(const FlowSetup& s, int n, int coarse_steps, std::vector<Check>& checks) {
  const Grid g = s.grid(n);
  std::vector<RunResult> runs;
  for (int m = 1; m <= 9; m *= 3)
    runs.push_back(integrate(g, s.params, s.flow, s.T / (coarse_steps * m), coarse_steps * m));
  std::vector<double> eu2, eum, ep2, epm;
  for (int i = 0; i < 2; ++i) {
    const auto du = velocity_difference(g, runs[i].last.u, runs[i + 1].last.u);
    const auto dp = pressure_difference(runs[i].last.p, runs[i + 1].p_before_last);
    eu2.push_back(du.l2);
    eum.push_back(du.max);
    ep2.push_back(dp.l2);
    epm.push_back(dp.max);
  }
  const std::string seq = " N=" + std::to_string(n) + ", " + std::to_string(coarse_steps) + "x3^k steps";
  checks.push_back({"order of u (L2), time," + seq, observed_order(eu2[0], eu2[1], 3.0), ">=", 1.9});
  checks.push_back({"order of u (max), time," + seq, observed_order(eum[0], eum[1], 3.0), ">=", 1.9});
  checks.push_back({"order of p (L2), time," + seq, observed_order(ep2[0], ep2[1], 3.0), ">=", 1.9});
  checks.push_back({"order of p (max), time," + seq, observed_order(epm[0], epm[1], 3.0), ">=", 1.9});
}

// ---------------------------------------------------------------------------------------------------------------

std::vector<Check> fluid_divergence(bool quick) {
  std::vector<Check> checks;
  const int m = quick ? 1 : 4;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int combo = 0; combo < 8; ++combo) {
    std::array<Boundary, 3> bc{};
    for (int a = 0; a < 3; ++a) bc[a] = (combo >> a) & 1 ? W : P;
    const Grid g({8 * m, 6 * m, 10 * m}, {8.0 * m, 6.0 * m, 10.0 * m}, bc);
    FluidParams prm;
    prm.rho = 1.3;
    prm.mu = 0.7;
    prm.body_force = {U(rng), U(rng), U(rng)};
    for (int a = 0; a < 3; ++a) {
      prm.wall_lower[a] = {U(rng), U(rng), U(rng)};
      prm.wall_upper[a] = {U(rng), U(rng), U(rng)};
      prm.wall_upper[a][a] = prm.wall_lower[a][a];
    }
    NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
    FluidState a = ns.initial_state(), b;
    FaceField force(g);
    for (int d = 0; d < 3; ++d) {
      for (double& v : a.u[d].values()) v = U(rng);
      for (double& v : force[d].values()) v = 10 * U(rng);
    }
    for (double& v : a.p.values()) v = U(rng);
    ns.apply_wall_values(a.u);
    double worst = 0;
    for (int n = 0; n < 3; ++n) {
      ns.step(a, force, 0.3, b);
      Array3 div;
      divergence(g, b.u, div);
      double dmax = 0;
      for (double v : div.values()) dmax = std::fmax(dmax, std::abs(v));
      worst = std::fmax(worst, dmax * g.h() / max_abs_velocity(g, b.u));
      std::swap(a, b);
    }
    std::string name = "max|D u| h / max|u| after projection, ";  // (+=: GCC 12 warns falsely on literal + string)
    name += bc_name(bc);
    checks.push_back({name, worst, "<=", 1e-12});
  }
  return checks;
}

std::vector<Check> fluid_solvers(bool quick) {
  std::vector<Check> checks;
  const int m = quick ? 1 : 4;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  static const char* names[4] = {"u", "v", "w", "p"};
  for (int l = 0; l < 4; ++l) {
    const Layout layout = static_cast<Layout>(l);
    double worst_helmholtz = 0, worst_poisson = 0;
    for (int combo = 0; combo < 8; ++combo) {
      std::array<Boundary, 3> bc{};
      for (int a = 0; a < 3; ++a) bc[a] = (combo >> a) & 1 ? W : P;
      const Grid g({6 * m, 10 * m, 8 * m}, {0.6, 1.0, 0.8}, bc);
      FftHelmholtzSolver solver(g, layout, FftPlanning::Estimate);
      const auto shape = layout == Layout::Pressure ? g.cell_shape() : g.face_shape(l);
      Array3 x(shape[0], shape[1], shape[2]);
      for (double& v : x.values()) v = U(rng);
      if (layout != Layout::Pressure && !g.periodic(l)) {  // wall faces are not unknowns: homogeneous
        for (int k = 0; k < shape[2]; ++k)
          for (int j = 0; j < shape[1]; ++j)
            for (int i = 0; i < shape[0]; ++i) {
              const int q = l == 0 ? i : (l == 1 ? j : k);
              if (q == 0 || q == g.n(l)) x(i, j, k) = 0;
            }
      }
      const double c = 0.8 * g.h() * g.h();
      for (int op = 0; op < 2; ++op) {
        const double alpha = op == 0 ? 1.0 : 0.0, beta = op == 0 ? -c : 1.0;
        Array3 b;
        apply_operator(g, layout, x, alpha, beta, b);
        Array3 sol = b;
        solver.solve(sol, alpha, beta);
        const double res = relative_residual(g, layout, sol, b, alpha, beta);
        (op == 0 ? worst_helmholtz : worst_poisson) = std::fmax(op == 0 ? worst_helmholtz : worst_poisson, res);
      }
    }
    checks.push_back({std::string("Helmholtz residual, layout ") + names[l] + ", all 8 boundary combinations",
                      worst_helmholtz, "<=", 1e-11});
    checks.push_back({std::string("Poisson residual, layout ") + names[l] + ", all 8 boundary combinations",
                      worst_poisson, "<=", 1e-11});
  }
  return checks;
}

std::vector<Check> taylor_green(bool quick) {
  TaylorGreen tg{2 * std::numbers::pi, 1.0, 0.02};
  FlowSetup s;
  s.grid = [](int n) { return Grid({n, n, 2}, {1.0, 1.0, 2.0 / n}, {P, P, P}); };
  s.params.rho = tg.rho;
  s.params.mu = tg.mu;
  s.flow = exact_flow(tg);
  s.T = 0.2;
  s.dt_per_h = 0.25;
  std::vector<Check> checks;
  space_study(s, quick ? std::vector<int>{24, 48, 96} : std::vector<int>{32, 64, 128, 256}, checks);
  time_study(s, quick ? 32 : 64, quick ? 8 : 16, checks);
  return checks;
}

std::vector<Check> abc_flow(bool quick) {
  AbcFlow abc{1.0, 0.8, 0.6, 1.0, 1.0, 0.1};
  FlowSetup s;
  s.grid = [](int n) {
    return Grid({n, n, n}, {2 * std::numbers::pi, 2 * std::numbers::pi, 2 * std::numbers::pi}, {P, P, P});
  };
  s.params.rho = abc.rho;
  s.params.mu = abc.mu;
  s.flow = exact_flow(abc);
  s.T = 0.4;
  s.dt_per_h = 0.25;
  std::vector<Check> checks;
  space_study(s, quick ? std::vector<int>{12, 24, 48} : std::vector<int>{16, 32, 64, 128}, checks);
  time_study(s, quick ? 16 : 32, quick ? 4 : 8, checks);
  return checks;
}

std::vector<Check> closed_box_mms(bool quick) {
  ClosedBoxMms mms{1.0, 0.1};
  FlowSetup s;
  s.grid = [](int n) { return Grid({n, n, n}, {1.0, 1.0, 1.0}, {W, W, W}); };
  s.params.rho = mms.rho;
  s.params.mu = mms.mu;
  s.flow = exact_flow(mms, [mms](const Grid& g) -> ForceFn {
              auto parts = std::make_shared<std::array<FaceField, 4>>();
              for (auto& f : *parts) f = FaceField(g);
              for (int d = 0; d < 3; ++d) {
                const Array3& shape = (*parts)[0][d];
                for (int k = 0; k < shape.nz(); ++k)
                  for (int j = 0; j < shape.ny(); ++j)
                    for (int i = 0; i < shape.nx(); ++i) {
                      const auto v = mms.force_parts(g.face_position(d, i, j, k));
                      for (int m = 0; m < 4; ++m) (*parts)[m][d](i, j, k) = v[m][d];
                    }
              }
              return [parts, mms](double t, FaceField& f) {
                const auto c = mms.force_coefficients(t);
                for (int d = 0; d < 3; ++d)
                  for (std::size_t n = 0; n < f[d].size(); ++n) {
                    double v = 0;
                    for (int i = 0; i < 4; ++i) v += c[i] * (*parts)[i][d][n];
                    f[d][n] = v;
                  }
              };
            });
  s.T = 0.25;
  s.dt_per_h = 0.2;
  std::vector<Check> checks;
  space_study(s, quick ? std::vector<int>{8, 16, 32} : std::vector<int>{12, 24, 48, 96}, checks);
  time_study(s, quick ? 16 : 32, quick ? 16 : 32, checks);
  return checks;
}

/// Start-up Couette flow: walls on z (moving in x and y), periodic x, y (two cells: the flow is 1D).
std::vector<Check> couette(bool quick) {
  CouetteStartup c;
  c.z_lower = -0.5;
  c.z_upper = 0.5;
  c.wall_lower = {-0.5, 0.25, 0};
  c.wall_upper = {0.5, -0.25, 0};
  FluidParams prm;
  prm.rho = c.rho;
  prm.mu = c.mu;
  prm.wall_lower[2] = c.wall_lower;
  prm.wall_upper[2] = c.wall_upper;
  const auto grid = [](int n) { return Grid({2, 2, n}, {2.0 / n, 2.0 / n, 1.0}, {P, P, W}, {0, 0, -0.5}); };
  // The series is smooth for t > 0: start from it at t0 (the impulsive start itself excites every grid mode,
  // which Crank–Nicolson damps only slowly) and compare at t0 + T.
  const double t0 = 0.02, T = 0.08;
  ExactFlow flow{
      [c, t0](const Vec3& x, double t) { return c.velocity(x, t0 + t); }, [](const Vec3&, double) { return 0.0; }, {}};
  std::vector<Check> checks;
  const std::vector<int> ns = quick ? std::vector<int>{16, 32, 64} : std::vector<int>{32, 64, 128, 256};
  std::vector<double> e2, em;
  for (int n : ns) {
    const Grid g = grid(n);
    const int steps = static_cast<int>(std::ceil(T / (g.h() / 16)));
    const RunResult r = integrate(g, prm, flow, T / steps, steps);
    const auto e = velocity_error(g, r.last.u, [&](const Vec3& x) { return c.velocity(x, t0 + T); });
    e2.push_back(e.l2);
    em.push_back(e.max);
  }
  const std::string seq = " N=" + std::to_string(ns.front()) + ".." + std::to_string(ns.back());
  checks.push_back({"order of u (L2) vs series, space," + seq, min_observed_order(e2), ">=", 1.9});
  checks.push_back({"order of u (max) vs series, space," + seq, min_observed_order(em), ">=", 1.9});

  // Steady state from rest on the finest grid against the linear profile (exact also for the discrete problem:
  // the ghost value 2u_w − u_0 extrapolates a linear profile exactly).
  const Grid g = grid(ns.back());
  NavierStokesSolver ns_solver(g, prm, FftPlanning::Estimate);
  FluidState a = ns_solver.initial_state(), b;
  const FaceField zero(g);
  const int steps = steps_to_steady(2.0, 4e-3, g.h(), c.mu / c.rho);
  for (int n = 0; n < steps; ++n) {
    ns_solver.step(a, zero, 2.0 / steps, b);
    std::swap(a, b);
  }
  const auto e = velocity_error(g, a.u, [&](const Vec3& x) { return c.steady(x); });
  checks.push_back({"steady state (t = 2) vs linear profile, max relative, N=" + std::to_string(ns.back()),
                    e.max / norm(c.wall_upper - c.wall_lower), "<=", 1e-6});
  return checks;
}

/// Pressure-driven flow along x in the duct |y| < a, |z| < b (walls), periodic x, driven by a body force G.
std::vector<Check> duct_poiseuille(bool quick) {
  std::vector<Check> checks;
  // The series against the published square-duct constants.
  const DuctPoiseuille square{1.0, 1.0, 1.0, 1.0};
  checks.push_back({"square duct: |Q mu/(a^4 G) - 0.5623081|", std::abs(square.flow_rate() - 0.5623081), "<=", 1e-7});
  checks.push_back(
      {"square duct: |u_centre mu/(a^2 G) - 0.2946854|", std::abs(square.velocity(0, 0) - 0.2946854), "<=", 1e-7});

  const DuctPoiseuille duct{1.0, 0.5, 1.0, 1.0};
  FluidParams prm;
  prm.mu = duct.mu;
  prm.body_force = {duct.G, 0, 0};
  const auto grid = [&](int n) {
    return Grid({2, 2 * n, n}, {2.0 / n, 2 * duct.a, 2 * duct.b}, {P, W, W}, {0, -duct.a, -duct.b});
  };
  // Discrete steady solution directly: μ ∇_h² u = −G, one transform solve on the u layout.
  const auto steady = [&](const Grid& g) {
    Array3 u(g.face_shape(0)[0], g.face_shape(0)[1], g.face_shape(0)[2], -duct.G / duct.mu);
    FftHelmholtzSolver(g, Layout::VelocityX, FftPlanning::Estimate).solve(u, 0.0, 1.0);
    return u;
  };
  const std::vector<int> ns = quick ? std::vector<int>{8, 16, 32} : std::vector<int>{16, 32, 64, 128};
  std::vector<double> e2, em, eq;
  for (int n : ns) {
    const Grid g = grid(n);
    const Array3 u = steady(g);
    double s2 = 0, smax = 0, q = 0;
    for (int k = 0; k < g.n(2); ++k)
      for (int j = 0; j < g.n(1); ++j) {
        const Vec3 x = g.face_position(0, 0, j, k);
        const double e = u(0, j, k) - duct.velocity(x.y, x.z);
        s2 += e * e;
        smax = std::fmax(smax, std::abs(e));
        q += u(0, j, k) * g.h() * g.h();
      }
    e2.push_back(std::sqrt(s2 / (g.n(1) * g.n(2))));
    em.push_back(smax);
    eq.push_back(std::abs(q - duct.flow_rate()));
  }
  const std::string seq = " N=" + std::to_string(ns.front()) + ".." + std::to_string(ns.back());
  checks.push_back({"order of discrete steady u (L2) vs series," + seq, min_observed_order(e2), ">=", 1.9});
  checks.push_back({"order of discrete steady u (max) vs series," + seq, min_observed_order(em), ">=", 1.9});
  checks.push_back({"order of flow rate vs series," + seq, min_observed_order(eq), ">=", 1.9});

  // Time stepping from rest reaches the discrete steady solution (the slowest mode decays like
  // exp(−ν π²/4 (1/a² + 1/b²) t), below 1e-15 at t = 3).
  const Grid g = grid(quick ? 32 : 64);  // ~500 steps; 2000 at N=128 take minutes
  const Array3 us = steady(g);
  NavierStokesSolver solver(g, prm, FftPlanning::Estimate);
  FluidState a = solver.initial_state(), b;
  const FaceField zero(g);
  const int steps = steps_to_steady(3.0, 1e-2, g.h(), prm.mu / prm.rho);
  for (int n = 0; n < steps; ++n) {
    solver.step(a, zero, 3.0 / steps, b);
    std::swap(a, b);
  }
  double diff = 0, umax = 0;
  for (std::size_t n = 0; n < us.size(); ++n) {
    diff = std::fmax(diff, std::abs(a.u[0][n] - us[n]));
    umax = std::fmax(umax, std::abs(us[n]));
  }
  for (int d = 1; d < 3; ++d)
    for (double v : a.u[d].values()) diff = std::fmax(diff, std::abs(v));
  checks.push_back({"time-stepped (t = 3) vs direct discrete steady u, max relative, N=" + std::to_string(g.n(2)),
                    diff / umax, "<=", 1e-6});
  checks.push_back({"direct discrete steady vs series, max relative, N=" + std::to_string(ns.back()),
                    em.back() / duct.velocity(0, 0), "<=", 1e-2});
  return checks;
}

}  // namespace

std::vector<Study> fluid_studies() {
  return {
      {"fluid_divergence", "discrete divergence after the projection (11)-(12), all 8 periodic/wall combinations",
       fluid_divergence},
      {"fluid_solvers", "residual of every FFTW Helmholtz/Poisson solver, every layout and boundary combination",
       fluid_solvers},
      {"taylor_green", "2D Taylor-Green vortex (extruded), periodic: orders in space and time for u and p",
       taylor_green},
      {"abc_flow", "Arnold-Beltrami-Childress flow, periodic: orders in space and time for u and p", abc_flow},
      {"couette", "start-up Couette flow between moving walls vs its series: order in space, steady state", couette},
      {"duct_poiseuille", "pressure-driven rectangular duct flow vs its series: order in space, steady state",
       duct_poiseuille},
      {"closed_box_mms", "manufactured flow in a closed box (6 no-slip walls): orders in space and time",
       closed_box_mms},
  };
}

}  // namespace immerse::verify
