#pragma once
// Advancing the membrane (paper §2.4): the schemes share this interface.
#include <memory>
#include <string>
#include <vector>

#include "immerse/timestep/CoupledOperator.hpp"
#include "immerse/timestep/StepStats.hpp"

namespace immerse {

/// Nonlinear-solver settings of the implicit schemes (§4: GMRES rtol 1e-3, Newton ||g||/||X|| < 1e-8).
struct SolverSettings {
  double theta = 0.5;           ///< theta-method weight: 1/2 is the trapezoidal rule (29), 1 backward Euler
  double newton_rtol = 1e-8;    ///< stop when ||g|| / ||X|| < newton_rtol
  double gmres_rtol = 1e-3;     ///< relative tolerance of each GMRES solve
  int max_newton_its = 20;      ///< a step that needs more is rejected
  int bfgs_memory = 20;         ///< limited-memory quasi-Newton: stored pairs
  std::string petsc_options;    ///< extra PETSc options, e.g. "-ksp_gmres_restart 50"
  void validate() const;
};

class MembraneIntegrator {
 public:
  virtual ~MembraneIntegrator() = default;
  /// Attempts one step of length dt. On success the operator is committed; on failure nothing is
  /// (stats.converged == false, stats.failure says why).
  virtual StepStats step(CoupledOperator& op, double dt) = 0;
  virtual std::string name() const = 0;

  /// Positions X^{n-1} and step dt^{n-1} before the committed ones, used by the implicit schemes' initial guess
  /// X^(0) = X^n + (dt/dt^{n-1})(X^n - X^{n-1}) (step 1 of §3); empty before the first step. Saved in checkpoints.
  const std::vector<double>& previous_positions() const { return prev_X_; }
  double previous_dt() const { return prev_dt_; }
  void set_history(std::vector<double> previous_positions, double previous_dt) {
    prev_X_ = std::move(previous_positions);
    prev_dt_ = previous_dt;
  }

 protected:
  /// Records X^n as history just before the operator commits X^{n+1}.
  void remember(const CoupledOperator& op, double dt) {
    prev_X_.assign(op.positions().begin(), op.positions().end());
    prev_dt_ = dt;
  }

 private:
  std::vector<double> prev_X_;
  double prev_dt_ = 0;
};

/// The schemes by name: "euler" (eq. 28), "rk2" (midpoint), "jfnk" (§2.4.3), "bfgs" (eq. 35, dense),
/// "lbfgs" (limited-memory quasi-Newton). Unknown names throw InputError.
std::unique_ptr<MembraneIntegrator> make_integrator(const std::string& name, const SolverSettings& settings);

/// The accepted names, for error messages and documentation.
const std::vector<std::string>& integrator_names();

}  // namespace immerse
