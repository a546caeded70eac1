// Verification of the membrane time integrators on the oscillating membrane of §4.1 (Table 1, Figs. 2, 4-6).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/timestep/SolverStats.hpp"
#include "immerse/verify/Convergence.hpp"
#include "immerse/verify/OscillatingMembrane.hpp"
#include "immerse/verify/Study.hpp"

namespace immerse::verify {

namespace {

struct Snapshot {
  std::vector<double> X;
  FaceField u;
};

Snapshot run_oscillating(int n, int level, double mu, double T, double dt, const SolverSettings& s = {}) {
  OscillatingMembrane exp(n, level, mu);
  auto jfnk = make_integrator("jfnk", s);
  exp.run_to(*jfnk, T, dt);
  const auto X = exp.op().positions();
  return {{X.begin(), X.end()}, exp.op().fluid_state().u};
}

// Discrete L2 norms of §4.1: Lagrangian with the node weights, Eulerian with h^3 over every velocity point.
double lagrangian_l2(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& w) {
  double s = 0;
  for (std::size_t i = 0; i < w.size(); ++i)
    for (int d = 0; d < 3; ++d) s += (a[3 * i + d] - b[3 * i + d]) * (a[3 * i + d] - b[3 * i + d]) * w[i];
  return std::sqrt(s);
}
double eulerian_l2(const FaceField& a, const FaceField& b, double h) {
  double s = 0;
  for (int d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a[d].size(); ++i) s += (a[d][i] - b[d][i]) * (a[d][i] - b[d][i]);
  return std::sqrt(s * h * h * h);
}

std::vector<Check> time_order(bool quick) {
  const int n = quick ? 16 : 64, level = quick ? 2 : 5;
  std::vector<Check> checks;
  const OscillatingMembrane probe(n, level, 0.01);
  for (double mu : {0.01, 0.005}) {
    std::vector<Snapshot> runs;
    for (int steps : {16, 32, 64, 128}) runs.push_back(run_oscillating(n, level, mu, 1.0, 1.0 / steps));
    std::vector<double> eX, eu;
    for (std::size_t k = 0; k + 1 < runs.size(); ++k) {
      eX.push_back(lagrangian_l2(runs[k].X, runs[k + 1].X, probe.node_weights()));
      eu.push_back(eulerian_l2(runs[k].u, runs[k + 1].u, probe.grid().h()));
    }
    const std::string m = "mu = " + std::to_string(mu).substr(0, 5);
    for (std::size_t k = 0; k < eX.size(); ++k) {
      const std::string dt = "dt = 1/" + std::to_string(16 << k);
      checks.push_back({"e_T(X; " + dt + "), " + m, eX[k], "<=", 1e-2});
      checks.push_back({"e_T(u; " + dt + "), " + m, eu[k], "<=", 1e-2});
    }
    checks.push_back({"order in time of X, " + m, min_observed_order(eX), ">=", 1.9});
    checks.push_back({"order in time of u, " + m, min_observed_order(eu), ">=", 1.9});
  }
  return checks;
}

// Largest distance of a node from the box centre: an unstable explicit run throws the membrane apart.
double max_radius(std::span<const double> X) {
  double r = 0;
  for (std::size_t i = 0; i < X.size(); i += 3)
    r = std::max(r, std::hypot(X[i] - 0.5, X[i + 1] - 0.5, X[i + 2] - 0.5));
  return std::isfinite(r) ? r : INFINITY;
}

struct Run {
  int steps = 0;
  int blowup_step = -1;  ///< first step at which the run was detected unstable (-1: stable)
  int max_newton = 0;
  double mean_newton = 0, mean_gmres = 0, mean_solves = 0;
  double x_undershoot = INFINITY;  ///< min over time of (x semi-extent - r_eq): < 0 once it oscillates past
  MembraneGeometry start, end;
};

// Runs §4.1 with fixed steps to T; an instability (a node leaving the box or beyond r = 0.45, non-finite
// values, a failed nonlinear solve) ends the run and is recorded with its step.
Run run_stability(const std::string& scheme, int n, int level, double mu, double dt, double T) {
  OscillatingMembrane exp(n, level, mu);
  auto integ = make_integrator(scheme, {});
  Run r;
  const auto X0 = exp.op().membrane_positions(0);
  r.start = measure(exp.mesh(), X0);
  const int steps = static_cast<int>(std::lround(T / dt));
  const double req = OscillatingMembrane::equilibrium_radius();
  for (int k = 1; k <= steps; ++k) {
    SolverStats st;
    try {
      st = integ->step(exp.op(), dt);
    } catch (const SimulationError&) {
      st.converged = false;
    }
    if (!st.converged || max_radius(exp.op().positions()) > 0.45) {
      r.blowup_step = k;
      break;
    }
    r.steps = k;
    r.max_newton = std::max(r.max_newton, st.newton_its);
    r.mean_newton += st.newton_its;
    r.mean_gmres += st.gmres_its;
    r.mean_solves += static_cast<double>(st.fluid_solves);
    const auto X = exp.op().positions();
    double xmin = INFINITY, xmax = -INFINITY;
    for (std::size_t i = 0; i < X.size(); i += 3) xmin = std::min(xmin, X[i]), xmax = std::max(xmax, X[i]);
    r.x_undershoot = std::min(r.x_undershoot, 0.5 * (xmax - xmin) - req);
  }
  if (r.steps > 0) {
    r.mean_newton /= r.steps;
    r.mean_gmres /= r.steps;
    r.mean_solves /= r.steps;
  }
  r.end = measure(exp.mesh(), exp.op().membrane_positions(0));
  return r;
}

std::vector<Check> stability(bool quick) {
  const int n = quick ? 32 : 64, level = quick ? 3 : 5;
  const double h = 1.0 / n, req = OscillatingMembrane::equilibrium_radius();
  std::vector<Check> checks;
  // Fig. 6: forward Euler at dt = 4 dx is unstable within a few tens of steps.
  const Run euler = run_stability("euler", n, level, 0.01, 4 * h, 10.0);
  checks.push_back({"forward Euler, dt = 4dx, mu = 0.01: step at which instability is detected",
                    euler.blowup_step < 0 ? std::numeric_limits<double>::infinity() : double(euler.blowup_step), "<=", 60});
  // Fig. 5: JFNK at dt = 4 dx, mu = 0.1, relaxes to the sphere of radius (abc)^(1/3).
  const Run slow = run_stability("jfnk", n, level, 0.1, 4 * h, 10.0);
  checks.push_back({"JFNK, dt = 4dx, mu = 0.1: steps completed to t = 10", double(slow.steps), ">=",
                    std::floor(10.0 / (4 * h))});
  double dev = 0;
  for (double ax : slow.end.semi_axes) dev = std::max(dev, std::abs(ax - req) / req);
  checks.push_back({"JFNK, mu = 0.1: max |semi-axis - 0.2224| / 0.2224 at t = 10", dev, "<=", 0.01});
  checks.push_back({"JFNK, mu = 0.1: enclosed volume drift |V(10) - V(0)| / V(0)",
                    std::abs(slow.end.volume - slow.start.volume) / slow.start.volume, "<=", 0.05});
  checks.push_back({"JFNK, dt = 4dx: max Newton iterations per step (Fig. 2b: 1-4)", double(slow.max_newton), "<=", 4});
  checks.push_back({"JFNK, dt = 4dx: mean GMRES iterations per Newton iteration (Fig. 2b: 1-4)",
                    slow.mean_gmres / std::max(slow.mean_newton, 1e-300), "<=", 4});
  checks.push_back({"JFNK, dt = 4dx: mean fluid solves per step", slow.mean_solves, "<=", 25});
  // Fig. 4: at mu = 0.01 the membrane oscillates (overshoots the sphere) and stays stable.
  const Run osc = run_stability("jfnk", n, level, 0.01, 4 * h, quick ? 5.0 : 10.0);
  checks.push_back({"JFNK, dt = 4dx, mu = 0.01: steps completed", double(osc.steps), ">=",
                    std::floor((quick ? 5.0 : 10.0) / (4 * h))});
  checks.push_back({"JFNK, mu = 0.01: x semi-extent undershoots r_eq (oscillation), min(a_x - r_eq)",
                    osc.x_undershoot, "<=", -1e-3});
  // Fig. 2a: dt = dx.
  const Run fine = run_stability("jfnk", n, level, 0.01, h, quick ? 1.0 : 10.0);
  checks.push_back({"JFNK, dt = dx: max Newton iterations per step (Fig. 2a: 1-4)", double(fine.max_newton), "<=", 4});
  checks.push_back({"JFNK, dt = dx: mean GMRES iterations per Newton iteration (Fig. 2a: 1-4)",
                    fine.mean_gmres / std::max(fine.mean_newton, 1e-300), "<=", 4});
  return checks;
}

// The same step from the same state, solved by JFNK, the dense BFGS of eq. (35), limited-memory BFGS and Anderson
// acceleration.
std::vector<Check> solver_agreement(bool quick) {
  const int n = quick ? 16 : 32, level = quick ? 2 : 3;
  SolverSettings s;
  s.newton_rtol = 1e-10;
  std::vector<std::vector<double>> X;
  std::vector<int> its;
  for (const char* scheme : {"jfnk", "bfgs", "lbfgs", "anderson"}) {
    OscillatingMembrane exp(n, level, 0.01);
    auto jfnk = make_integrator("jfnk", s);
    exp.run_to(*jfnk, 2.0 / n, 1.0 / n);  // two identical JFNK steps first, so the third has history
    auto integ = make_integrator(scheme, s);
    integ->set_history(jfnk->previous_positions(), jfnk->previous_dt(), jfnk->guess_errors().errors());
    const auto st = integ->step(exp.op(), 1.0 / n);
    if (!st.converged) throw SimulationError(std::string(scheme) + " step failed: " + st.failure);
    its.push_back(st.newton_its);
    X.emplace_back(exp.op().positions().begin(), exp.op().positions().end());
  }
  auto rel = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0, m = 0;
    for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]), m += a[i] * a[i];
    return std::sqrt(d / m);
  };
  return {{"||X_bfgs - X_jfnk|| / ||X|| (Newton tolerance 1e-10)", rel(X[1], X[0]), "<=", 1e-9},
          {"||X_lbfgs - X_jfnk|| / ||X||", rel(X[2], X[0]), "<=", 1e-9},
          {"||X_anderson - X_jfnk|| / ||X||", rel(X[3], X[0]), "<=", 1e-9},
          {"Anderson iterations for the step", double(its[3]), "<=", 8},
          {"dense BFGS iterations for the step", double(its[1]), "<=", 20},
          {"L-BFGS iterations for the step", double(its[2]), "<=", 20}};
}

// §4.1 at mu = 0.1 with a step of 32 dx, far beyond the relaxation time of the membrane's short modes: after the
// shape has relaxed (t = 24), the trapezoidal rule (theta = 1/2, not L-stable) still carries ringing stiff modes
// (node speeds alternating step to step), backward Euler (theta = 1) has damped them.
std::vector<Check> theta_ringing(bool quick) {
  const int n = quick ? 16 : 32, level = quick ? 2 : 3, steps = 12;
  const double dt = 32.0 / n;
  auto final_speed = [&](double theta) {
    OscillatingMembrane exp(n, level, 0.1);
    SolverSettings s;
    s.theta = theta;
    auto jfnk = make_integrator("jfnk", s);
    for (int k = 0; k < steps; ++k)
      if (const auto st = jfnk->step(exp.op(), dt); !st.converged) throw SimulationError(st.failure);
    double umax = 0;
    for (double u : exp.op().node_velocity()) umax = std::max(umax, std::abs(u));
    return umax;
  };
  const double trap = final_speed(0.5), be = final_speed(1.0);
  return {{"trapezoidal (theta = 1/2), dt = 32dx: max node speed at t = 24 (ringing)", trap, ">=", 1e-3},
          {"backward Euler (theta = 1), dt = 32dx: max node speed at t = 24", be, "<=", 2e-4},
          {"ratio trapezoidal / backward Euler", trap / be, ">=", 10}};
}

}  // namespace

std::vector<Study> integrator_studies() {
  return {
      {"oscillating_time_order",
       "§4.1 Table 1: time-discretization errors e_T of X and u at T = 1, dt = 1/16..1/128, JFNK trapezoidal",
       time_order},
      {"oscillating_stability",
       "§4.1 Figs. 2, 4-6: dt = 4dx breaks forward Euler, JFNK stays stable and relaxes to r = (abc)^(1/3)",
       stability},
      {"theta_ringing",
       "§4.1 at dt = 32dx: the trapezoidal rule rings (stiff modes not damped), backward Euler (theta = 1) does not",
       theta_ringing},
      {"quasi_newton_agreement",
       "§2.4.2-2.4.3: dense BFGS (eq. 35), L-BFGS, Anderson acceleration and JFNK reach the same X^{n+1}",
       solver_agreement},
  };
}

}  // namespace immerse::verify
