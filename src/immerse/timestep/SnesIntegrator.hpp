#pragma once
// Implicit membrane update solved with PETSc SNES (paper §2.4.2-2.4.3, algorithm of §3):
//
//   solve g(X^{n+1}) = 0, g from eq. (31) (theta-method; theta = 1/2 is the trapezoidal rule (29)),
//   starting from X^(0) = 2X^n - X^{n-1} (step 1 of §3), plus the error GuessErrorPredictor predicts for it when
//   solver.initial_guess = "recurrence" (the default),
//   stopping when ||g|| / ||X|| < newton_rtol (§4: 1e-8).
//
// Method::NewtonKrylov ("jfnk", §2.4.3): Newton steps (33)-(34), each solved by unpreconditioned GMRES
// (relative tolerance 1e-3, §4; it also stops once its residual, the linearized ||g|| after the step, is below
// 0.9 newton_rtol ||X^(0)||: the Newton test is then met unless the nonlinear and finite-difference terms of the
// step exceed a tenth of the tolerance; on §4.4 they are about 1 % of it; and it gives up as stalled when its
// residual has not halved over the last 30 iterations, so that a step too stiff for unpreconditioned GMRES is
// rejected and halved at once instead of after the iteration limit) whose matrix-vector product is the
// finite difference (36)
//   J(X) y ~ (g(X + eps y) - g(X)) / eps,   eps = sqrt((1 + ||X||) eps_mach) / ||y||   (37),
// which is PETSc's matrix-free Jacobian with the Walker-Pernice parameter (MATMFFD_WP). Full Newton steps.
// Method::LimitedMemoryBFGS ("lbfgs"): PETSc's limited-memory quasi-Newton (SNESQN, LBFGS) with H_0 = I, the
// memory-light counterpart of eq. (35) that runs on 3D meshes where the dense matrix cannot (§2.4.2).
// Method::Anderson ("anderson"): Anderson acceleration (PETSc's SNESANDERSON; Walker & Ni, SIAM J. Numer. Anal.
// 49 (2011) 1715) of the fixed-point map X -> X - beta g(X), depth m (solver.anderson_memory, _beta):
//
//   X^(k+1) = sum_i a_i (X^(i) - beta g(X^(i))),   i = k-m..k,   the a_i (sum 1) minimizing || sum_i a_i g(X^(i)) ||.
//
// Every evaluation of g is one fluid solve and each one both tests convergence and adds a direction, whereas a
// Newton step of JFNK spends its last evaluation on the test alone: on a residual that is nearly linear and whose
// Jacobian J = I - (dt/2) dU/dX has its spectrum close to 1 on the error left by the initial guess (soft cells:
// §4.4 at mu0 = 10 uN/m) that saves about one solve per step. On stiff membranes (J's spectrum far from 1) the
// fixed-point step amplifies the stiff modes and the mixing converges slowly or not at all: there JFNK is the robust
// choice (docs/time-integration.md, "Anderson acceleration").
//
// Positions are measured in the operator's length scale inside the solver, so that eq. (37)'s perturbation is
// relative to the geometry whatever the physical units (docs/theory/conventions.md, "The implicit step").
// Every PETSc option stays overridable through SolverSettings::petsc_options and the environment variable
// PETSC_OPTIONS (the former wins; both win over the settings); an option that no PETSc object of the solver, nor
// PETSc itself, has used by the end of the first solve that iterates is an InputError (docs/user-guide.md, "PETSc
// options").
//
// Distributed (a communicator other than PETSC_COMM_SELF, given at construction: make_integrator's overload with
// one): each process passes the operator of the membranes it owns (DistributedOperator), whose size() is its share of
// the unknowns. The vectors are PETSc MPI vectors with that local size, and SNES, KSP and MatMFFD live on the
// communicator, so every norm and inner product is global and the mathematics, tolerances and the GMRES stall test
// are those above. The residual callback evaluates g on the local part (the operator's trial_velocity is collective);
// after each evaluation the processes agree on whether it failed anywhere, so that a SimulationError on one process
// fails the attempt on all (the others report that it failed on another process). When the local number of unknowns
// changed on any process (membranes migrated at the last commit), every process recreates the solver and its vectors
// at the start of the step. The history of the initial guess is per process and per membrane (MembraneIntegrator);
// DistributedSimulation moves it with the membranes. Every method is collective on the communicator.
// Verified by: the studies oscillating_time_order, oscillating_stability, theta_ringing and quasi_newton_agreement,
// and the tests Integrators.*, PetscOptionsTest.* and PetscOptionsBoth.*; distributed: ParallelRun.* (the quick
// red-cell channel with JFNK, Anderson and L-BFGS on 1 to 4 processes against the one-process run).
#include <petscsnes.h>

#include <exception>
#include <memory>

#include "immerse/timestep/MembraneIntegrator.hpp"
#include "immerse/timestep/ThetaResidual.hpp"

namespace immerse {

class SnesIntegrator final : public MembraneIntegrator {
 public:
  enum class Method { NewtonKrylov, LimitedMemoryBFGS, Anderson };
  /// `comm`: the processes that share the unknowns (PETSC_COMM_SELF: all of them here, sequential vectors).
  SnesIntegrator(Method method, const SolverSettings& settings, MPI_Comm comm = PETSC_COMM_SELF);
  ~SnesIntegrator() override;
  SnesIntegrator(const SnesIntegrator&) = delete;
  SnesIntegrator& operator=(const SnesIntegrator&) = delete;

  SolverStats step(CoupledOperator& op, double dt) override;
  std::string name() const override;
  /// Creates the PETSc solver with PETSC_OPTIONS and solver.petsc_options applied; a value PETSc rejects is an
  /// InputError.
  void prepare(std::size_t unknowns) override;

 private:
  void setup(std::size_t n);
  // Sets a PETSc option of this solver (its private options database) from a setting, unless solver.petsc_options
  // gives it.
  void set_option(const char* name, double value);
  static void insert_options(PetscOptions options, const char* source, const std::string& text);
  // "PETSC_OPTIONS = '...', solver.petsc_options = '...'" as far as given, for error messages.
  std::string options_given() const;
  // InputError naming each option of the solver's database that nothing used.
  void check_options_used();
  void destroy();
  static PetscErrorCode form_function(SNES, Vec x, Vec f, void* ctx);
  static PetscErrorCode converged(SNES, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm,
                                  SNESConvergedReason* reason, void* ctx);
  static PetscErrorCode gmres_converged(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason* reason,
                                        void* ctx);

  // Whether any process of comm_ reports `flag` (collective; false at once on PETSC_COMM_SELF).
  bool any_process(bool flag) const;

  Method method_;
  SolverSettings settings_;
  MPI_Comm comm_;
  bool distributed_;  // comm_ is not PETSC_COMM_SELF: MPI vectors, agreement on sizes and failures
  std::string environment_options_;  // PETSC_OPTIONS
  PetscOptions options_ = nullptr;     // PETSC_OPTIONS, then solver.petsc_options, then the settings' options
  bool options_checked_ = false;
  SNES snes_ = nullptr;
  Mat J_ = nullptr;
  Vec x_ = nullptr, r_ = nullptr;
  std::size_t n_ = 0;

  // Per-step context for the callbacks.
  ThetaResidual* residual_ = nullptr;
  double scale_ = 1.0;
  std::vector<double> X_, g_;
  std::exception_ptr callback_error_;
  double last_ratio_ = 0;
  // -ksp_atol given (solver.petsc_options or PETSC_OPTIONS): it replaces the stop at 0.9 of the Newton tolerance.
  PetscBool user_atol_ = PETSC_FALSE;
  void* ksp_default_ctx_ = nullptr;  // PETSc's default KSP test, which gmres_converged extends
  std::vector<double> gmres_history_;  // the current solve's residual norms
  bool gmres_stalled_ = false;         // a solve of this step stalled
};

}  // namespace immerse
