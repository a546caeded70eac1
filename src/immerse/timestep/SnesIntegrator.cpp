#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/timestep/SnesIntegrator.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/timestep/LogEvent.hpp"
#include "immerse/timestep/PetscSession.hpp"

namespace immerse {
namespace {

// GMRES stops once the linearized residual is below this fraction of the Newton tolerance (header comment).
constexpr double kGmresShareOfNewtonTolerance = 0.9;
// GMRES gives up as stalled when its residual has not fallen below kStallFactor of its value kStallWindow
// iterations earlier (header comment). Converging solves of §4.4 gain far more: a factor 1000 in 16-23 iterations
// at mu0 = 1 mN/m, 20-60 in 11-26 for the second Newton solve.
constexpr std::size_t kStallWindow = 30;
constexpr double kStallFactor = 0.5;

}  // namespace

SnesIntegrator::SnesIntegrator(Method method, const SolverSettings& settings, MPI_Comm comm)
    : method_(method), settings_(settings), comm_(comm), distributed_(comm != PETSC_COMM_SELF) {
  settings_.validate();
  if (const char* env = std::getenv("PETSC_OPTIONS")) environment_options_ = env;
  IMMERSE_PETSC(PetscOptionsCreate(&options_));
  // PETSC_OPTIONS first, so that solver.petsc_options wins where both give an option.
  insert_options(options_, "PETSC_OPTIONS", environment_options_);
  insert_options(options_, "solver.petsc_options", settings_.petsc_options);
  // PETSc's global database, which PetscInitialize filled from PETSC_OPTIONS, takes solver.petsc_options too: it
  // holds the options PETSc reads at PetscFinalize, and the table -log_view prints.
  insert_options(nullptr, "solver.petsc_options", settings_.petsc_options);
  // Options PETSc reads from its global database count as used here; PetscInitialize started logging only if
  // PETSC_OPTIONS asked for it.
  PetscBool log_view = PETSC_FALSE, given = PETSC_FALSE, logging = PETSC_FALSE;
  IMMERSE_PETSC(PetscOptionsHasName(options_, nullptr, "-log_view", &log_view));
  IMMERSE_PETSC(PetscOptionsHasName(options_, nullptr, "-options_left", &given));
  IMMERSE_PETSC(PetscOptionsHasName(options_, nullptr, "-options_view", &given));
  IMMERSE_PETSC(PetscLogIsActive(&logging));
  if (log_view && !logging) IMMERSE_PETSC(PetscLogDefaultBegin());
}

SnesIntegrator::~SnesIntegrator() {
  destroy();
  if (!options_) return;
  // The options this solver used count as used in the global database too, which -options_left reports on.
  PetscInt left = 0;
  char **names = nullptr, **values = nullptr;
  if (PetscOptionsLeftGet(nullptr, &left, &names, &values) == 0) {
    for (PetscInt i = 0; i < left; ++i) {
      PetscBool used = PETSC_FALSE, given = PETSC_FALSE;
      std::string option(1, '-');
      option += names[i];
      if (PetscOptionsUsed(options_, names[i], &used) == 0 && used)
        PetscOptionsHasName(nullptr, nullptr, option.c_str(), &given);
    }
    PetscOptionsLeftRestore(nullptr, &left, &names, &values);
  }
  PetscOptionsDestroy(&options_);
}

void SnesIntegrator::insert_options(PetscOptions options, const char* source, const std::string& text) {
  if (!text.empty() && PetscOptionsInsertString(options, text.c_str()) != 0)
    throw InputError(std::string(source) + " = '" + echoed(text) + "': PETSc cannot parse it");
}

std::string SnesIntegrator::options_given() const {
  std::string s = environment_options_.empty() ? "" : "PETSC_OPTIONS = '" + echoed(environment_options_) + "'";
  if (s.empty() || !settings_.petsc_options.empty())
    s += (s.empty() ? "" : ", ") + std::string("solver.petsc_options = '") + echoed(settings_.petsc_options) + "'";
  return s;
}

void SnesIntegrator::check_options_used() {
  options_checked_ = true;
  PetscInt left = 0;
  char **names = nullptr, **values = nullptr;
  IMMERSE_PETSC(PetscOptionsLeftGet(options_, &left, &names, &values));
  const std::vector<std::string> unused(names, names + left);
  IMMERSE_PETSC(PetscOptionsLeftRestore(options_, &left, &names, &values));
  PetscOptions config = nullptr;  // solver.petsc_options alone: where an unused option came from
  IMMERSE_PETSC(PetscOptionsCreate(&config));
  PetscOptionsInsertString(config, settings_.petsc_options.c_str());  // parsed once already (constructor)
  std::string from_config, from_environment;
  int count = 0;
  for (const std::string& n : unused) {
    std::string option(1, '-');
    option += n;
    PetscBool in_config = PETSC_FALSE, read_at_start = PETSC_FALSE;  // by PetscInitialize, e.g. -malloc_debug
    PetscOptionsHasName(config, nullptr, option.c_str(), &in_config);
    PetscOptionsUsed(nullptr, n.c_str(), &read_at_start);
    if (!in_config && read_at_start) continue;
    std::string& list = in_config ? from_config : from_environment;
    list += (list.empty() ? "" : ", ") + echoed(option);
    ++count;
  }
  PetscOptionsDestroy(&config);
  if (count == 0) return;
  auto part = [](const char* source, const std::string& list) {
    if (list.empty()) return std::string();
    return std::string(source) + (list.find(',') == std::string::npos ? ": option " : ": options ") + list;
  };
  std::string parts = part("solver.petsc_options", from_config);
  if (!from_environment.empty()) parts += (parts.empty() ? "" : "; ") + part("PETSC_OPTIONS", from_environment);
  throw InputError(parts + (count == 1 ? " was" : " were") + " used by none of the '" + name() +
                   "' solver's PETSc objects (" +
                   (method_ == Method::NewtonKrylov ? "SNES, KSP, PC, MatMFFD" : "SNES only: no KSP, PC or MatMFFD") +
                   ") in its first solve, nor by PETSc itself: misspelt, or an option of another object (see "
                   "PETSc's -help)");
}

void SnesIntegrator::destroy() {
  if (snes_) SNESDestroy(&snes_);
  if (ksp_default_ctx_) KSPConvergedDefaultDestroy(ksp_default_ctx_);
  ksp_default_ctx_ = nullptr;
  if (J_) MatDestroy(&J_);
  if (x_) VecDestroy(&x_);
  if (r_) VecDestroy(&r_);
}

void SnesIntegrator::setup(std::size_t n) {
  n_ = n;
  const auto N = static_cast<PetscInt>(n);
  if (distributed_)
    IMMERSE_PETSC(VecCreateMPI(comm_, N, PETSC_DETERMINE, &x_));  // the local part: the owned membranes' unknowns
  else
    IMMERSE_PETSC(VecCreateSeq(PETSC_COMM_SELF, N, &x_));
  IMMERSE_PETSC(VecDuplicate(x_, &r_));
  IMMERSE_PETSC(SNESCreate(comm_, &snes_));
  IMMERSE_PETSC(PetscObjectSetOptions(reinterpret_cast<PetscObject>(snes_), options_));
  IMMERSE_PETSC(SNESSetFunction(snes_, r_, &SnesIntegrator::form_function, this));
  IMMERSE_PETSC(SNESSetConvergenceTest(snes_, &SnesIntegrator::converged, this, nullptr));
  IMMERSE_PETSC(SNESSetTolerances(snes_, 0.0, 0.0, 0.0, settings_.max_newton_its, 1000000));
  SNESLineSearch ls;
  if (method_ == Method::NewtonKrylov) {
    IMMERSE_PETSC(SNESSetType(snes_, SNESNEWTONLS));
    IMMERSE_PETSC(MatCreateSNESMF(snes_, &J_));
    IMMERSE_PETSC(PetscObjectSetOptions(reinterpret_cast<PetscObject>(J_), options_));
    IMMERSE_PETSC(MatMFFDSetType(J_, MATMFFD_WP));  // eq. (37)
    {  // -mat_mffd_* options are read by the matrix's MatMFFD context, a PETSc object of its own
      void* mffd = nullptr;
      IMMERSE_PETSC(MatShellGetContext(J_, &mffd));
      IMMERSE_PETSC(PetscObjectSetOptions(static_cast<PetscObject>(mffd), options_));
      IMMERSE_PETSC(MatSetFromOptions(J_));
    }
    IMMERSE_PETSC(SNESSetJacobian(snes_, J_, J_, MatMFFDComputeJacobian, nullptr));
    KSP ksp;
    PC pc;
    IMMERSE_PETSC(SNESGetKSP(snes_, &ksp));
    IMMERSE_PETSC(KSPSetType(ksp, KSPGMRES));
    IMMERSE_PETSC(KSPSetTolerances(ksp, settings_.gmres_rtol, PETSC_DEFAULT, PETSC_DEFAULT, 200));
    IMMERSE_PETSC(KSPGetPC(ksp, &pc));
    IMMERSE_PETSC(PCSetType(pc, PCNONE));  // the paper's GMRES is unpreconditioned
    IMMERSE_PETSC(KSPConvergedDefaultCreate(&ksp_default_ctx_));
    IMMERSE_PETSC(KSPSetConvergenceTest(ksp, &SnesIntegrator::gmres_converged, this, nullptr));
    IMMERSE_PETSC(PetscOptionsHasName(options_, nullptr, "-ksp_atol", &user_atol_));
  } else if (method_ == Method::Anderson) {
    IMMERSE_PETSC(SNESSetType(snes_, SNESANDERSON));
    set_option("-snes_anderson_m", settings_.anderson_memory);
    set_option("-snes_anderson_beta", settings_.anderson_beta);
  } else {
    IMMERSE_PETSC(SNESSetType(snes_, SNESQN));
    IMMERSE_PETSC(SNESQNSetType(snes_, SNES_QN_LBFGS));
    IMMERSE_PETSC(SNESQNSetScaleType(snes_, SNES_QN_SCALE_NONE));  // H_0 = I: J = I - (dt/2) u' (32)
    IMMERSE_PETSC(SNESQNSetRestartType(snes_, SNES_QN_RESTART_NONE));
    set_option("-snes_qn_m", settings_.bfgs_memory);
  }
  IMMERSE_PETSC(SNESGetLineSearch(snes_, &ls));
  IMMERSE_PETSC(SNESLineSearchSetType(ls, SNESLINESEARCHBASIC));  // full steps: eq. (34) (Anderson takes none)
  IMMERSE_PETSC(SNESSetSolution(snes_, x_));
  try {
    IMMERSE_PETSC(SNESSetFromOptions(snes_));
    IMMERSE_PETSC(SNESSetUp(snes_));
  } catch (const std::runtime_error& e) {
    throw InputError(options_given() + ": " + e.what());
  }
}

void SnesIntegrator::set_option(const char* name, double value) {
  PetscBool given = PETSC_FALSE;  // solver.petsc_options and PETSC_OPTIONS win over the setting
  IMMERSE_PETSC(PetscOptionsHasName(options_, nullptr, name, &given));
  if (given) return;
  std::ostringstream v;
  v.precision(17);
  v << value;
  IMMERSE_PETSC(PetscOptionsSetValue(options_, name, v.str().c_str()));
}

std::string SnesIntegrator::name() const {
  switch (method_) {
    case Method::NewtonKrylov: return "jfnk";
    case Method::LimitedMemoryBFGS: return "lbfgs";
    case Method::Anderson: return "anderson";
  }
  return "";
}

PetscErrorCode SnesIntegrator::form_function(SNES, Vec x, Vec f, void* ctx) {
  const LogEvent event(Phase::ImplicitResidual);
  auto* self = static_cast<SnesIntegrator*>(ctx);
  const PetscScalar* xs;
  PetscScalar* fs;
  PetscCall(VecGetArrayRead(x, &xs));
  const long n = static_cast<long>(self->n_);
  const double scale = self->scale_;
  double* const X = self->X_.data();
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
  for (long i = 0; i < n; ++i) X[i] = scale * xs[i];
  PetscCall(VecRestoreArrayRead(x, &xs));
  // 0: evaluated; 1: a SimulationError; 2: another exception. Distributed, the largest over the processes.
  int failure = 0;
  try {
    (*self->residual_)(self->X_, self->g_);
  } catch (const SimulationError&) {
    self->callback_error_ = std::current_exception();
    failure = 1;
  } catch (...) {
    self->callback_error_ = std::current_exception();
    failure = 2;
  }
  if (self->distributed_) {
    int anywhere = 0;
    if (MPI_Allreduce(&failure, &anywhere, 1, MPI_INT, MPI_MAX, self->comm_) != MPI_SUCCESS) return PETSC_ERR_MPI;
    if (anywhere > failure)
      self->callback_error_ = anywhere == 1 ? std::make_exception_ptr(SimulationError(
                                                  "the residual could not be evaluated on another process"))
                                            : std::make_exception_ptr(std::runtime_error(
                                                  "the residual could not be evaluated on another process"));
    failure = anywhere;
  }
  if (failure != 0) return PETSC_ERR_USER;
  PetscCall(VecGetArray(f, &fs));
  const double* const g = self->g_.data();
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
  for (long i = 0; i < n; ++i) fs[i] = g[i] / scale;
  PetscCall(VecRestoreArray(f, &fs));
  return 0;
}

PetscErrorCode SnesIntegrator::converged(SNES snes, PetscInt it, PetscReal, PetscReal, PetscReal fnorm,
                                         SNESConvergedReason* reason, void* ctx) {
  auto* self = static_cast<SnesIntegrator*>(ctx);
  Vec x;
  PetscReal xnorm;
  PetscCall(SNESGetSolution(snes, &x));
  PetscCall(VecNorm(x, NORM_2, &xnorm));
  self->last_ratio_ = fnorm / xnorm;  // ||g|| / ||X||, independent of the scaling
  *reason = SNES_CONVERGED_ITERATING;
  if (!std::isfinite(fnorm))
    *reason = SNES_DIVERGED_FNORM_NAN;
  else if (fnorm <= self->settings_.newton_rtol * xnorm)
    *reason = SNES_CONVERGED_FNORM_RELATIVE;
  else if (it >= self->settings_.max_newton_its)
    *reason = SNES_DIVERGED_MAX_IT;
  return 0;
}

PetscErrorCode SnesIntegrator::gmres_converged(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason* reason,
                                               void* ctx) {
  auto* self = static_cast<SnesIntegrator*>(ctx);
  PetscCall(KSPConvergedDefault(ksp, it, rnorm, reason, self->ksp_default_ctx_));
  auto& h = self->gmres_history_;
  if (it == 0) h.clear();
  h.push_back(rnorm);
  if (*reason == KSP_CONVERGED_ITERATING && h.size() > kStallWindow &&
      !(rnorm < kStallFactor * h[h.size() - 1 - kStallWindow])) {
    *reason = KSP_DIVERGED_BREAKDOWN;
    self->gmres_stalled_ = true;
  }
  return 0;
}

bool SnesIntegrator::any_process(bool flag) const {
  if (!distributed_) return flag;
  int mine = flag ? 1 : 0, any = 0;
  check_mpi(MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm_), "MPI_Allreduce");
  return any != 0;
}

void SnesIntegrator::prepare(std::size_t unknowns) {
  if (!snes_) setup(unknowns);
}

SolverStats SnesIntegrator::step(CoupledOperator& op, double dt) {
  // PETSc's L-BFGS keeps its secant pairs from one solve to the next; each step starts afresh from H_0 = I instead,
  // so that a step depends only on the state a checkpoint holds (bitwise restarts).
  if (method_ == Method::LimitedMemoryBFGS) destroy();
  // Distributed: membranes that migrated at the last commit changed the local sizes; all processes start afresh.
  if (distributed_ && snes_ && any_process(op.size() != n_)) destroy();
  if (!snes_) setup(op.size());
  if (op.size() != n_) throw std::logic_error("SnesIntegrator: the number of unknowns changed");
  SolverStats stats;
  const std::size_t solves0 = op.fluid_solves();
  ThetaResidual residual(op, dt, settings_.theta);
  residual_ = &residual;
  scale_ = op.length_scale();
  X_.resize(n_);
  g_.resize(n_);
  callback_error_ = nullptr;
  gmres_stalled_ = false;

  PetscScalar* xs;
  IMMERSE_PETSC(VecGetArray(x_, &xs));
  initial_guess(residual, settings_.initial_guess, X_);  // X_: the positions of the last evaluation, reused
  {
    const long n = static_cast<long>(n_);
    const double* const X = X_.data();
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
    for (long i = 0; i < n; ++i) xs[i] = X[i] / scale_;
  }
  IMMERSE_PETSC(VecRestoreArray(x_, &xs));
  if (method_ == Method::NewtonKrylov && !user_atol_) {  // GMRES's absolute stop: 0.9 of the Newton tolerance
    PetscReal xnorm;
    KSP ksp;
    IMMERSE_PETSC(VecNorm(x_, NORM_2, &xnorm));
    IMMERSE_PETSC(SNESGetKSP(snes_, &ksp));
    const double atol = kGmresShareOfNewtonTolerance * settings_.newton_rtol * xnorm;
    IMMERSE_PETSC(KSPSetTolerances(ksp, PETSC_DEFAULT, atol, PETSC_DEFAULT, PETSC_DEFAULT));
  }

  const PetscErrorCode ierr = SNESSolve(snes_, nullptr, x_);
  residual_ = nullptr;
  PetscInt its = 0, lits = 0;
  SNESGetIterationNumber(snes_, &its);
  SNESGetLinearSolveIterations(snes_, &lits);
  stats.newton_its = static_cast<int>(its);
  stats.gmres_its = static_cast<int>(lits);
  stats.residual = last_ratio_;
  // Some options are read only while solving (-snes_converged_reason, -ksp_view): checked once a solve has iterated.
  if (!options_checked_ && ierr == 0 && (its > 0 || lits > 0)) check_options_used();
  SNESConvergedReason reason = SNES_CONVERGED_ITERATING;
  if (ierr == 0) SNESGetConvergedReason(snes_, &reason);
  if (ierr != 0 || reason <= 0) {
    stats.converged = false;
    if (callback_error_) {
      try {
        std::rethrow_exception(callback_error_);
      } catch (const SimulationError& e) {
        stats.failure = e.what();
      }
    } else if (ierr != 0) {
      check_petsc(ierr, "SNESSolve");
    } else {
      stats.failure = std::string("nonlinear solve did not converge (") + SNESConvergedReasons[reason] + ") after " +
                      std::to_string(its) + " iterations, ||g||/||X|| = " + std::to_string(last_ratio_);
      if (gmres_stalled_)
        stats.failure += "; GMRES stalled: its residual did not halve in " + std::to_string(kStallWindow) +
                         " iterations (the membranes are too stiff for this dt without a preconditioner)";
    }
    stats.fluid_solves = op.fluid_solves() - solves0;
    return stats;
  }
  const PetscScalar* xr;
  IMMERSE_PETSC(VecGetArrayRead(x_, &xr));
  for (std::size_t i = 0; i < n_; ++i) X_[i] = scale_ * xr[i];
  IMMERSE_PETSC(VecRestoreArrayRead(x_, &xr));
  // The trial fluid state must be the one driven by the accepted positions.
  if (any_process(!residual.trial_matches(X_))) residual(X_, g_);  // distributed: agreed, as it is collective
  remember(op, dt, X_);
  op.commit(X_, dt);
  stats.fluid_solves = op.fluid_solves() - solves0;
  return stats;
}

}  // namespace immerse
