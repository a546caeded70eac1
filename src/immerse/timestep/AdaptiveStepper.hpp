#pragma once
// Step-size control around a membrane integrator: a step whose nonlinear solve fails (no convergence within the
// iteration limit, a non-finite residual, a trial position outside the domain) is rejected, nothing is committed,
// and it is retried with half the step; after `grow_after` accepted steps the step doubles again, back up to the
// nominal one. Below the floor dt_min the run stops with a SimulationError. Never silently accepts a failed step.
// Verified by the tests AdaptiveStepper.* (halves on failure and grows back, nothing committed; stops below the
// floor).
#include <functional>
#include <string>

#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class AdaptiveStepper {
 public:
  AdaptiveStepper(double dt_nominal, double dt_min, int grow_after = 4);

  struct Accepted {
    SolverStats stats;  ///< of the accepted attempt (fluid solves include the rejected attempts)
    double dt;        ///< the step taken
    int rejected;     ///< attempts rejected before it
  };
  /// Advances one accepted step of at most max_dt (the caller's clamp to the end time). Each rejection is reported
  /// through `log` with its reason and the new step; when `stop_requested` then returns true, StopRequested is
  /// thrown instead of retrying.
  Accepted advance(MembraneIntegrator& integrator, CoupledOperator& op, double max_dt,
                   const std::function<void(const std::string&)>& log,
                   const std::function<bool()>& stop_requested = {});

  double dt() const { return dt_; }
  double nominal_dt() const { return nominal_; }
  /// Restores the controller (checkpoint restart).
  void set_state(double dt, int successes) { dt_ = dt; successes_ = successes; }
  int successes() const { return successes_; }

 private:
  double nominal_, dt_, dt_min_;
  int grow_after_, successes_ = 0;
};

}  // namespace immerse
