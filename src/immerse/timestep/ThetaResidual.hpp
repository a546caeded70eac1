#pragma once
// The residual of the implicit membrane update, eqs. (29)-(31) generalized to the theta-method:
//
//   g(X) = X - X^n - dt [ (1 - theta) U^n + theta J(X) u^{n+1}(X) ],                       (31)
//
// where u^{n+1}(X) is one fluid step from the committed state driven by
//   F^{n+1/2} = (1 - theta) S(X^n) f(X^n) + theta S(X) f(X).
// theta = 1/2 is the trapezoidal rule (29) of the paper; the force is then centred in time as well, which is what
// makes the coupled step second order for both X and u (Table 1; docs/theory/conventions.md). theta = 1 is backward Euler
// (L-stable: no ringing of stiff membrane modes at large dt). g is a pure function of X: the committed state is
// never changed, so GMRES may evaluate it as often as it needs (each evaluation is one fluid solve).
// Verified by: the studies oscillating_time_order (theta = 1/2) and theta_ringing (theta = 1/2 rings, theta = 1
// does not), and the tests Integrators.TrapezoidalJfnkIsSecondOrderForPositionAndVelocity, Integrators.BackwardEuler*.
#include <span>
#include <vector>

#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/timestep/CoupledOperator.hpp"

namespace immerse {

class ThetaResidual {
 public:
  ThetaResidual(CoupledOperator& op, double dt, double theta) : op_(op), dt_(dt), theta_(theta), U_(op.size()) {}

  /// g = g(X), eq. (31).
  void operator()(std::span<const double> X, std::span<double> g) {
    op_.trial_velocity(X, theta_, X, dt_, U_);
    const auto Xn = op_.positions();
    const auto Un = op_.node_velocity();
    const long n = static_cast<long>(X.size());
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
    for (long i = 0; i < n; ++i) g[i] = X[i] - Xn[i] - dt_ * ((1.0 - theta_) * Un[i] + theta_ * U_[i]);
  }
  /// True when the operator's trial state was produced by exactly these positions (so it can be committed).
  bool trial_matches(std::span<const double> X) const { return op_.trial_matches(X); }
  /// Initial guess X^(0) = X^n + (dt/dt^{n-1})(X^n - X^{n-1}) (step 1 of §3: 2X^n - X^{n-1} for equal steps);
  /// X^n + dt U^n on the first step.
  void initial_guess(const std::vector<double>& previous, double previous_dt, std::span<double> X0) const {
    const auto Xn = op_.positions();
    const auto Un = op_.node_velocity();
    const long n = static_cast<long>(Xn.size());
    if (previous.size() == Xn.size() && previous_dt > 0) {
      const double r = dt_ / previous_dt;
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
      for (long i = 0; i < n; ++i) X0[i] = Xn[i] + r * (Xn[i] - previous[i]);
    } else {
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
      for (long i = 0; i < n; ++i) X0[i] = Xn[i] + dt_ * Un[i];
    }
  }
  CoupledOperator& op() { return op_; }
  const CoupledOperator& op() const { return op_; }
  double dt() const { return dt_; }

 private:
  CoupledOperator& op_;
  double dt_, theta_;
  std::vector<double> U_;
};

}  // namespace immerse
