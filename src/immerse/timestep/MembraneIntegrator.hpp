#pragma once
// Advancing the membrane (paper §2.4): the schemes share this interface.
#include <mpi.h>

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "immerse/timestep/CoupledOperator.hpp"
#include "immerse/timestep/GuessErrorPredictor.hpp"
#include "immerse/timestep/SolverStats.hpp"
#include "immerse/timestep/ThetaResidual.hpp"

namespace immerse {

/// Nonlinear-solver settings of the implicit schemes (§4: GMRES rtol 1e-3, Newton ||g||/||X|| < 1e-8).
struct SolverSettings {
  /// Newton's starting point: the linear extrapolation of §3 step 1, or that plus the error GuessErrorPredictor
  /// predicts.
  enum class InitialGuess { Extrapolation, Recurrence };
  double theta = 0.5;           ///< theta-method weight: 1/2 is the trapezoidal rule (29), 1 backward Euler
  double newton_rtol = 1e-8;    ///< stop when ||g|| / ||X|| < newton_rtol
  double gmres_rtol = 1e-3;     ///< relative tolerance of each GMRES solve
  int max_newton_its = 20;      ///< a step that needs more is rejected
  int bfgs_memory = 20;         ///< limited-memory quasi-Newton: stored pairs
  int anderson_memory = 5;      ///< Anderson acceleration: residual differences mixed (its depth m)
  double anderson_beta = 0.85;  ///< Anderson acceleration: the mixing (damping) parameter beta
  std::string petsc_options;    ///< extra PETSc options, e.g. "-ksp_gmres_restart 50"
  InitialGuess initial_guess = InitialGuess::Recurrence;
  void validate() const;
};

class MembraneIntegrator {
 public:
  virtual ~MembraneIntegrator() = default;
  /// Attempts one step of length dt. On success the operator is committed; on failure nothing is
  /// (stats.converged == false, stats.failure says why).
  virtual SolverStats step(CoupledOperator& op, double dt) = 0;
  virtual std::string name() const = 0;
  /// Sets the scheme up for `unknowns` unknowns before the first step, so that a run reports solver options PETSc
  /// rejects (InputError) before it writes anything. Optional: step() sets up what it needs.
  virtual void prepare(std::size_t /*unknowns*/) {}

  /// Positions X^{n-1} and step dt^{n-1} before the committed ones, used by the implicit schemes' initial guess
  /// X^(0) = X^n + (dt/dt^{n-1})(X^n - X^{n-1}) (step 1 of §3); empty before the first step. Saved in checkpoints,
  /// with the errors of the last extrapolations (GuessErrorPredictor, all recorded with step dt^{n-1}).
  const std::vector<double>& previous_positions() const { return prev_X_; }
  double previous_dt() const { return prev_dt_; }
  const GuessErrorPredictor& guess_errors() const { return errors_; }
  void set_history(std::vector<double> previous_positions, double previous_dt,
                   std::span<const double> guess_errors = {});
  /// The same with the number of stored guess errors given, which also holds for vectors of length 0 (a process of
  /// a distributed run owning no membrane, whose history DistributedSimulation re-orders after a migration).
  void set_history(std::vector<double> previous_positions, double previous_dt, std::span<const double> guess_errors,
                   std::size_t guess_error_count);

 protected:
  /// X^(0) of the implicit schemes: the linear extrapolation (ThetaResidual::initial_guess), plus the error
  /// GuessErrorPredictor predicts for it when `guess` is Recurrence.
  void initial_guess(const ThetaResidual& g, SolverSettings::InitialGuess guess, std::span<double> X0);
  /// Records X^n as history just before the operator commits X^{n+1} = X; an implicit scheme passes X, so that
  /// the error of its extrapolated X^(0) is recorded.
  void remember(const CoupledOperator& op, double dt, std::span<const double> X = {});

 private:
  std::vector<double> prev_X_;
  double prev_dt_ = 0;
  std::vector<double> extrapolated_;  // this step's linear extrapolation, when extrapolated_valid_
  bool extrapolated_valid_ = false;   // X^(0) was the extrapolation (a flag: there may be no unknowns)
  GuessErrorPredictor errors_;
};

/// The schemes by name: "euler" (eq. 28), "rk2" (midpoint), "jfnk" (§2.4.3), "bfgs" (eq. 35, dense),
/// "lbfgs" (limited-memory quasi-Newton), "anderson" (Anderson acceleration of the same implicit update).
/// Unknown names throw InputError.
std::unique_ptr<MembraneIntegrator> make_integrator(const std::string& name, const SolverSettings& settings);
/// The same for unknowns shared by the processes of `comm` (each passing the operator of its share): the implicit
/// schemes "jfnk", "lbfgs" and "anderson" on PETSc MPI vectors (SnesIntegrator.hpp); the explicit ones, which combine
/// the unknowns one by one, unchanged. "bfgs" (a dense matrix over all unknowns) is an InputError unless `comm` is
/// PETSC_COMM_SELF. Collective.
std::unique_ptr<MembraneIntegrator> make_integrator(const std::string& name, const SolverSettings& settings,
                                                    MPI_Comm comm);

/// The accepted names, for error messages and documentation.
const std::vector<std::string>& integrator_names();

}  // namespace immerse
