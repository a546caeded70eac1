#pragma once
// Wall time spent in each part of the coupled step of §3 (ImmersedBoundaryOperator): the profile of a run by
// component. The nonlinear solver's own work (vector operations, the finite differences of eq. 36) is what a
// caller's total wall time leaves over.
#include <chrono>
#include <string>
#include <utility>

#include "immerse/timestep/LogEvent.hpp"

namespace immerse {

struct StepTimings {
  double force = 0;        ///< membrane forces f(X) of all membranes (§2.3), seconds
  double contact = 0;      ///< contact forces between membranes and with the walls (ContactForce)
  double spread = 0;       ///< S(X) f (eq. 6)
  double fluid = 0;        ///< the fluid step (eqs. 9-13) with its force F^{n+1/2}
  double interpolate = 0;  ///< J(X) u (eq. 14)

  double total() const { return force + contact + spread + fluid + interpolate; }
  /// The time spent between two readings `earlier` and *this of the same operator.
  StepTimings since(const StepTimings& earlier) const {
    return {force - earlier.force, contact - earlier.contact, spread - earlier.spread, fluid - earlier.fluid,
            interpolate - earlier.interpolate};
  }
  /// One line: each part (and the rest of `wall_seconds`, the wall time of `steps` steps) in ms per step and in
  /// per cent of the wall time.
  std::string profile(double wall_seconds, long steps) const;
};

/// Runs f and adds its wall time to `seconds`.
template <class F>
void timed(double& seconds, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  std::forward<F>(f)();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Runs f as a phase of the step profile: its wall time on this process is added to `seconds`, and it is PETSc's
/// log event `phase`.
template <class F>
void timed(double& seconds, Phase phase, F&& f) {
  const LogEvent event(phase);
  timed(seconds, std::forward<F>(f));
}

}  // namespace immerse
