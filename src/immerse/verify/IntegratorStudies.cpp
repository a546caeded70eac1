// Verification of the membrane time integrators on the oscillating membrane of §4.1 (Table 1, Figs. 2, 4-6).
#include <algorithm>
#include <cmath>
#include <iostream>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
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

}  // namespace

std::vector<Study> integrator_studies() {
  return {
      {"oscillating_time_order",
       "§4.1 Table 1: time-discretization errors e_T of X and u at T = 1, dt = 1/16..1/128, JFNK trapezoidal",
       time_order},
  };
}

}  // namespace immerse::verify
