#include "immerse/simulation/DistributedSimulation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/simulation/CheckpointEntries.hpp"
#include "immerse/simulation/RunSetup.hpp"

namespace immerse {

namespace {

/// The configuration, refused (InputError) where it asks for what is not distributed yet.
const io::Config& distributable(const io::Config& config) {
  const std::string scheme = config.get<std::string>("time.scheme");
  if (scheme != "euler" && scheme != "rk2")
    throw InputError("time.scheme = \"" + scheme +
                     "\": a distributed run takes the explicit schemes \"euler\" and \"rk2\" only (the implicit "
                     "schemes' vectors are not distributed yet)");
  for (std::size_t i = 0; i < config.count("membrane"); ++i) {
    const io::Config& m = config.entry("membrane", i);
    const std::string name = "membrane[" + std::to_string(i) + "]";
    if (m.get<double>("viscosity_ratio") != 1.0)
      throw InputError(name + ".viscosity_ratio = " + m.value_text("viscosity_ratio") +
                       ": a viscosity contrast (variable viscosity) is not distributed yet (run in one process)");
    if (m.get<std::string>("volume_correction") != "none")
      throw InputError(name + ".volume_correction = " + m.value_text("volume_correction") +
                       ": the volume correction is not distributed yet (run in one process)");
  }
  return config;
}

}  // namespace

DistributedSimulation::DistributedSimulation(const io::Config& config, Communicator comm)
    : config_(distributable(config)),
      dt_(config.get<double>("time.dt")),
      end_time_(config.get<double>("time.end")),
      max_speed_(config.get<double>("time.max_speed")),
      grid_(run_grid(config)),
      fluid_(grid_, run_fluid_params(config), comm),
      coupler_(fluid_.decomposition(), delta_kernel(config.get<std::string>("coupling.kernel"))),
      membranes_(build_membrane_set(config, grid_)) {
  require(std::isfinite(dt_) && dt_ > 0, "time.dt", dt_, "a finite step > 0");
  std::vector<const ElasticMembrane*> ms;
  for (const auto& m : membranes_.membranes) ms.push_back(m.get());
  op_ = std::make_unique<DistributedOperator>(
      fluid_, coupler_, std::move(ms), membranes_.initial, membranes_.references,
      fluid_.scatter(run_initial_fluid_state(config_, grid_, fluid_.params())), run_contact_settings(config_));
  integrator_ = make_integrator(config_.get<std::string>("time.scheme"), run_solver_settings(config_));
}

bool DistributedSimulation::finished() const { return time() >= end_time_ * (1 - 1e-12); }

void DistributedSimulation::advance() {
  const double dt = std::min(dt_, end_time_ - time());
  std::ostringstream where;
  where.precision(10);
  where << "step " << step_ + 1 << ", t = " << time() << ": ";
  try {
    integrator_->step(*op_, dt);
  } catch (const SimulationError& e) {
    throw SimulationError(where.str() + e.what());
  }
  ++step_;
  check_stability();
}

void DistributedSimulation::check_stability() const {
  // As Simulation's check: every owned node's position and velocity finite and its speed |U| within time.max_speed,
  // then the fluid velocity and pressure on this process's slab.
  const auto X = op_->positions();
  const auto U = op_->node_velocity();
  const auto offsets = op_->membrane_offsets();
  std::string what;
  for (std::size_t i = 0; i + 2 < X.size() && what.empty(); i += 3) {
    const Vec3 x{X[i], X[i + 1], X[i + 2]}, u{U[i], U[i + 1], U[i + 2]};
    if (isfinite(x) && isfinite(u) && norm(u) <= max_speed_) continue;
    const auto k = static_cast<std::size_t>(std::upper_bound(offsets.begin(), offsets.end(), i) - offsets.begin()) - 1;
    std::ostringstream s;
    s.precision(10);
    s << "unstable at step " << step_ << ", t = " << time() << ": membrane[" << op_->ownership().owned()[k].id
      << "] node " << (i - offsets[k]) / 3 << " "
      << (!isfinite(x)   ? "position is not finite"
          : !isfinite(u) ? "velocity is not finite"
                         : "speed exceeds time.max_speed (runaway)")
      << " (|u| = " << norm(u) << " m/s, bound " << max_speed_ << " m/s)";
    what = s.str();
  }
  const FluidState& f = op_->fluid_state();
  for (int d = 0; d < 3 && what.empty(); ++d)
    for (double v : f.u[d].values())
      if (!(std::abs(v) <= max_speed_)) {
        std::ostringstream s;
        s.precision(10);
        s << "unstable at step " << step_ << ", t = " << time() << ": fluid velocity u_" << "xyz"[d]
          << " is not finite or exceeds time.max_speed (runaway)";
        what = s.str();
        break;
      }
  if (what.empty() && !std::ranges::all_of(f.p.values(), [](double v) { return std::isfinite(v); })) {
    std::ostringstream s;
    s.precision(10);
    s << "unstable at step " << step_ << ", t = " << time() << ": fluid pressure is not finite";
    what = s.str();
  }
  const Communicator& comm = fluid_.decomposition().communicator();
  // Every process stops with the message of the lowest-ranked process that found the run unstable.
  if (const std::string first = first_error(comm, what); !first.empty()) throw SimulationError(first);
}

void DistributedSimulation::restore(const io::Checkpoint& ck) {
  check_checkpoint_configuration(config_, ck);
  const CheckpointEntries entries(ck);
  // The whole-grid state, checked entry by entry as Simulation::restore does, then cut into this run's slabs.
  FluidState f = run_initial_fluid_state(config_, grid_, fluid_.params());
  for (int d = 0; d < 3; ++d) {
    const std::size_t n = f.u[d].values().size();
    f.u[d].values() = entries.array("fluid.u" + std::to_string(d), n);
    if (f.adv[d].size() != f.u[d].size()) f.adv[d] = f.u[d];
    f.adv[d].values() = entries.array("fluid.adv" + std::to_string(d), n);
  }
  f.p.values() = entries.array("fluid.p", f.p.values().size());
  f.dt_prev = entries.time_value("fluid.dt_prev");
  if (ck.has("fluid.p_prev")) {
    if (f.p_prev.size() != f.p.size()) f.p_prev = f.p;
    f.p_prev.values() = entries.array("fluid.p_prev", f.p.values().size());
    f.dt_prev2 = entries.time_value("fluid.dt_prev2");
  }
  f.step = entries.count("fluid.step");
  f.time = entries.time_value("fluid.time");
  const std::size_t M = num_membranes();
  std::vector<std::vector<Vec3>> X(M);
  std::vector<std::size_t> first(M + 1, 0);  // of each membrane's unknowns in the global concatenation
  for (std::size_t m = 0; m < M; ++m) {
    const std::string name = "membrane[" + std::to_string(m) + "]";
    const auto& R = membranes_.references[m];
    if (ck.array(name + ".reference") != std::vector<double>(&R[0].x, &R[0].x + 3 * R.size()))
      throw InputError("checkpoint: the reference state of " + name +
                       " differs from the one this configuration builds (was its mesh file changed?)");
    const auto& a3 = entries.array(name + ".positions", 3 * R.size());
    X[m].resize(a3.size() / 3);
    for (std::size_t i = 0; i < X[m].size(); ++i) X[m][i] = {a3[3 * i], a3[3 * i + 1], a3[3 * i + 2]};
    first[m + 1] = first[m] + a3.size();
  }
  const std::size_t unknowns = first[M];
  const std::string previous = "integrator.previous_positions", errors = "integrator.guess_errors";
  const auto& prev_X = entries.array(previous, ck.array(previous).empty() ? 0 : unknowns);
  const double prev_dt = entries.time_value("integrator.previous_dt");
  const std::vector<double> guess_errors =
      ck.has(errors) ? entries.array(errors, ck.array(errors).size()) : std::vector<double>{};
  if (guess_errors.size() % std::max<std::size_t>(unknowns, 1) != 0)
    ck.invalid(errors, "has " + std::to_string(guess_errors.size()) + " values, not a multiple of the " +
                           std::to_string(unknowns) + " unknowns");
  const double dt = ck.get_double("stepper.dt");
  entries.number("stepper.dt", dt, std::isfinite(dt) && dt > 0 && dt <= dt_, "in (0, time.dt]");
  entries.count("stepper.successes");
  const std::int64_t step = entries.count("step");
  if (f.time >= end_time_ * (1 - 1e-12)) {
    std::ostringstream s;
    s << "time.end = " << end_time_ << ": must be later than the time of the checkpoint " << ck.source() << ", t = "
      << f.time << " (nothing left to run)";
    throw InputError(s.str());
  }
  std::vector<const ElasticMembrane*> ms;
  for (const auto& m : membranes_.membranes) ms.push_back(m.get());
  op_ = std::make_unique<DistributedOperator>(fluid_, coupler_, std::move(ms), X, membranes_.references,
                                              fluid_.scatter(f), run_contact_settings(config_));
  // The history of the nodes this process now owns, in its order (each stored vector: all unknowns, global order).
  const auto owned_part = [&](std::span<const double> global) {
    std::vector<double> part;
    for (std::size_t k = 0; k < global.size() / std::max<std::size_t>(unknowns, 1); ++k)
      for (const OwnedMembrane& m : op_->ownership().owned()) {
        const auto id = static_cast<std::size_t>(m.id);
        const auto from = global.begin() + static_cast<std::ptrdiff_t>(k * unknowns + first[id]);
        part.insert(part.end(), from, from + static_cast<std::ptrdiff_t>(first[id + 1] - first[id]));
      }
    return part;
  };
  integrator_->set_history(owned_part(prev_X), prev_dt, owned_part(guess_errors));
  step_ = step;
}

}  // namespace immerse
