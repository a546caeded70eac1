#pragma once
#include <cstddef>
#include <string>

namespace immerse {

/// What the nonlinear solver did in one attempt at a membrane time step (recorded in the run's diagnostics).
struct SolverStats {
  bool converged = true;       ///< false: the step was not accepted (nothing committed)
  int newton_its = 0;          ///< nonlinear iterations (Newton or quasi-Newton)
  int gmres_its = 0;           ///< Krylov iterations summed over the Newton steps
  std::size_t fluid_solves = 0; ///< fluid steps performed (each g(X) evaluation is one)
  double residual = 0;         ///< final ||g|| / ||X|| (0 for explicit schemes)
  std::string failure;         ///< why the step was not accepted
};

}  // namespace immerse
