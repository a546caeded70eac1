#pragma once
// PETSc log events of the coupled step, so that -log_view profiles a run as its last lines do (StepTimings): one
// class "immerse" with an event per phase. A LogEvent spans one phase while it lives; with logging off (no
// -log_view) it costs one pointer test.
#include <petsclog.h>

namespace immerse {

enum class Phase {
  MembraneForces,    ///< "MembraneForces": f(X) of all membranes (§2.3)
  Contact,           ///< "ContactForces": the contact forces (ContactForce)
  Spreading,         ///< "Spreading": S(X) f (eq. 6)
  FluidStep,         ///< "FluidStep": the fluid step (eqs. 9-13)
  Interpolation,     ///< "Interpolation": J(X) u (eq. 14)
  ImplicitResidual,  ///< "ImplicitResidual": one evaluation of g(X) (eq. 31) by the nonlinear solver
};

class LogEvent {
 public:
  explicit LogEvent(Phase phase);
  ~LogEvent();
  LogEvent(const LogEvent&) = delete;
  LogEvent& operator=(const LogEvent&) = delete;

 private:
  PetscLogEvent event_ = -1;  // -1: logging was off when the phase began
};

}  // namespace immerse
