#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/timestep/DenseBfgs.hpp"
#include "immerse/timestep/ForwardEuler.hpp"
#include "immerse/timestep/MidpointRK2.hpp"
#include "immerse/timestep/SnesIntegrator.hpp"

namespace immerse {

void SolverSettings::validate() const {
  require(theta >= 0.5 && theta <= 1.0, "time.theta", theta, "in [0.5, 1] (0.5 trapezoidal, 1 backward Euler)");
  require(std::isfinite(newton_rtol) && newton_rtol > 0 && newton_rtol < 1, "solver.newton_rtol", newton_rtol,
          "in (0, 1)");
  require(std::isfinite(gmres_rtol) && gmres_rtol > 0 && gmres_rtol < 1, "solver.gmres_rtol", gmres_rtol,
          "in (0, 1)");
  require(max_newton_its >= 1, "solver.max_newton_its", max_newton_its, "an integer >= 1");
  require(bfgs_memory >= 1, "solver.bfgs_memory", bfgs_memory, "an integer >= 1");
  require(anderson_memory >= 1, "solver.anderson_memory", anderson_memory, "an integer >= 1");
  require(std::isfinite(anderson_beta) && anderson_beta > 0 && anderson_beta <= 2, "solver.anderson_beta",
          anderson_beta, "in (0, 2]");
}

void MembraneIntegrator::set_history(std::vector<double> previous_positions, double previous_dt,
                                     std::span<const double> guess_errors) {
  errors_.restore(guess_errors, previous_positions.size(), previous_dt);
  prev_X_ = std::move(previous_positions);
  prev_dt_ = previous_dt;
}

void MembraneIntegrator::set_history(std::vector<double> previous_positions, double previous_dt,
                                     std::span<const double> guess_errors, std::size_t guess_error_count) {
  errors_.restore(guess_errors, previous_positions.size(), guess_error_count, previous_dt);
  prev_X_ = std::move(previous_positions);
  prev_dt_ = previous_dt;
}

void MembraneIntegrator::initial_guess(const ThetaResidual& g, SolverSettings::InitialGuess guess,
                                       std::span<double> X0) {
  g.initial_guess(prev_X_, prev_dt_, X0);
  extrapolated_.clear();
  extrapolated_valid_ = false;
  // Only an extrapolation over a step equal to the last one is recorded: the errors scale with the steps.
  if (guess != SolverSettings::InitialGuess::Recurrence || prev_X_.size() != X0.size() || prev_dt_ != g.dt())
    return;
  extrapolated_.assign(X0.begin(), X0.end());
  extrapolated_valid_ = true;
  errors_.predict(g.dt(), g.op().positions(), X0, g.op().membrane_offsets());
}

void MembraneIntegrator::remember(const CoupledOperator& op, double dt, std::span<const double> X) {
  if (extrapolated_valid_ && X.size() == extrapolated_.size()) {
    const long n = static_cast<long>(X.size());
    double* const e = extrapolated_.data();
#pragma omp parallel for schedule(static) if (n >= kMinValuesForThreads)
    for (long i = 0; i < n; ++i) e[i] = X[i] - e[i];
    errors_.record(dt, extrapolated_);
  } else {
    errors_.clear();
  }
  extrapolated_.clear();
  extrapolated_valid_ = false;
  prev_X_.assign(op.positions().begin(), op.positions().end());
  prev_dt_ = dt;
}

const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names{"euler", "rk2", "jfnk", "bfgs", "lbfgs", "anderson"};
  return names;
}

std::unique_ptr<MembraneIntegrator> make_integrator(const std::string& name, const SolverSettings& settings) {
  return make_integrator(name, settings, PETSC_COMM_SELF);
}

std::unique_ptr<MembraneIntegrator> make_integrator(const std::string& name, const SolverSettings& settings,
                                                    MPI_Comm comm) {
  settings.validate();
  if (name == "euler") return std::make_unique<ForwardEuler>();
  if (name == "rk2") return std::make_unique<MidpointRK2>();
  if (name == "jfnk") return std::make_unique<SnesIntegrator>(SnesIntegrator::Method::NewtonKrylov, settings, comm);
  if (name == "lbfgs")
    return std::make_unique<SnesIntegrator>(SnesIntegrator::Method::LimitedMemoryBFGS, settings, comm);
  if (name == "anderson") return std::make_unique<SnesIntegrator>(SnesIntegrator::Method::Anderson, settings, comm);
  if (name == "bfgs") {
    if (comm != PETSC_COMM_SELF)
      throw InputError("time.scheme = \"bfgs\": the dense quasi-Newton matrix of eq. (35) is not distributed (use "
                       "\"jfnk\", \"anderson\" or \"lbfgs\", or run in one process)");
    return std::make_unique<DenseBfgs>(settings);
  }
  throw InputError("time.scheme = '" + name + "': must be one of euler, rk2, jfnk, bfgs, lbfgs, anderson");
}

}  // namespace immerse
