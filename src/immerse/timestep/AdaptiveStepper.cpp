#include "immerse/timestep/AdaptiveStepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"

namespace immerse {

AdaptiveStepper::AdaptiveStepper(double dt_nominal, double dt_min, int grow_after)
    : nominal_(dt_nominal), dt_(dt_nominal), dt_min_(dt_min), grow_after_(grow_after) {
  require(std::isfinite(dt_nominal) && dt_nominal > 0, "time.dt", dt_nominal, "a finite step > 0");
  require(std::isfinite(dt_min) && dt_min > 0 && dt_min <= dt_nominal, "time.dt_min", dt_min, "in (0, time.dt]");
  require(grow_after >= 1, "time.grow_after", grow_after, "an integer >= 1");
}

AdaptiveStepper::Accepted AdaptiveStepper::advance(MembraneIntegrator& integrator, CoupledOperator& op,
                                                   double max_dt,
                                                   const std::function<void(const std::string&)>& log,
                                                   const std::function<bool()>& stop_requested) {
  const std::size_t solves0 = op.fluid_solves();
  int rejected = 0;
  for (;;) {
    const double dt = std::min(dt_, max_dt);
    SolverStats st = integrator.step(op, dt);
    if (st.converged) {
      st.fluid_solves = op.fluid_solves() - solves0;
      if (dt_ < nominal_ && ++successes_ >= grow_after_) {
        dt_ = std::min(2 * dt_, nominal_);
        successes_ = 0;
      }
      return {st, dt, rejected};
    }
    ++rejected;
    successes_ = 0;
    dt_ = 0.5 * dt;
    std::ostringstream s;
    s << "step rejected with dt = " << dt << " (" << st.failure << ")";
    if (dt_ < dt_min_) {
      s << "; the halved step " << dt_ << " is below time.dt_min = " << dt_min_;
      throw SimulationError(s.str());
    }
    if (stop_requested && stop_requested()) throw StopRequested(s.str() + "; not retried: a stop was requested");
    s << "; retrying with dt = " << dt_;
    log(s.str());
  }
}

}  // namespace immerse
