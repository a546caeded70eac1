#include "immerse/timestep/DenseBfgs.hpp"

#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/timestep/ThetaResidual.hpp"

namespace immerse {

namespace {
double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

DenseBfgs::DenseBfgs(const SolverSettings& settings) : settings_(settings) { settings_.validate(); }

SolverStats DenseBfgs::step(CoupledOperator& op, double dt) {
  const std::size_t n = op.size(), solves0 = op.fluid_solves();
  if (n > max_unknowns)
    throw InputError("time.scheme = 'bfgs': the dense quasi-Newton matrix needs " + std::to_string(n) + "^2 entries; " +
                     "it is limited to " + std::to_string(max_unknowns) +
                     " unknowns (use 'jfnk', 'anderson' or 'lbfgs')");
  SolverStats stats;
  ThetaResidual g(op, dt, settings_.theta);
  X_.resize(n);
  g_.resize(n);
  Xn_.resize(n);
  gn_.resize(n);
  p_.resize(n);
  q_.resize(n);
  Hq_.resize(n);
  H_.assign(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) H_[i * n + i] = 1.0;

  try {
    initial_guess(g, settings_.initial_guess, X_);
    g(X_, g_);
    for (int k = 0;; ++k) {
      stats.residual = std::sqrt(dot(g_, g_) / dot(X_, X_));
      if (!std::isfinite(stats.residual)) {
        stats.converged = false;
        stats.failure = "quasi-Newton residual is not finite at iteration " + std::to_string(k);
        break;
      }
      if (stats.residual < settings_.newton_rtol) break;
      if (k >= settings_.max_newton_its) {
        stats.converged = false;
        stats.failure = "quasi-Newton did not converge in " + std::to_string(k) +
                        " iterations, ||g||/||X|| = " + std::to_string(stats.residual);
        break;
      }
      // p = -H g, X <- X + p
#pragma omp parallel for
      for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (std::size_t j = 0; j < n; ++j) s += H_[i * n + j] * g_[j];
        p_[i] = -s;
      }
      for (std::size_t i = 0; i < n; ++i) Xn_[i] = X_[i] + p_[i];
      g(Xn_, gn_);
      for (std::size_t i = 0; i < n; ++i) q_[i] = gn_[i] - g_[i];
      ++stats.newton_its;
      const double pq = dot(p_, q_);
      if (std::abs(pq) > 1e-300) {
#pragma omp parallel for
        for (std::size_t i = 0; i < n; ++i) {
          double s = 0;
          for (std::size_t j = 0; j < n; ++j) s += H_[i * n + j] * q_[j];
          Hq_[i] = s;
        }
        // H stays symmetric (H_0 = I and the update is symmetric), so q^T H = (H q)^T.
        const double qHq = dot(q_, Hq_);
        const double c = (1.0 + qHq / pq) / pq;  // eq. (35), gamma = theta = 1
#pragma omp parallel for
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = 0; j < n; ++j)
            H_[i * n + j] += c * p_[i] * p_[j] - (p_[i] * Hq_[j] + Hq_[i] * p_[j]) / pq;
      }
      std::swap(X_, Xn_);
      std::swap(g_, gn_);
    }
  } catch (const SimulationError& e) {
    stats.converged = false;
    stats.failure = e.what();
  }
  if (stats.converged) {
    if (!g.trial_matches(X_)) g(X_, g_);
    remember(op, dt, X_);
    op.commit(X_, dt);
  }
  stats.fluid_solves = op.fluid_solves() - solves0;
  return stats;
}

}  // namespace immerse
