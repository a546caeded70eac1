#include "immerse/simulation/DistributedSimulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/membrane/VolumeCorrection.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/simulation/CheckpointEntries.hpp"
#include "immerse/simulation/RunSetup.hpp"

namespace immerse {

namespace {

/// The configuration, refused (InputError) where it asks for what is not distributed yet.
const io::Config& distributable(const io::Config& config) {
  if (config.get<std::string>("time.scheme") == "bfgs")
    throw InputError("time.scheme = \"bfgs\": the dense quasi-Newton matrix of eq. (35) is not distributed (use "
                     "\"jfnk\", \"anderson\" or \"lbfgs\", or run in one process)");
  return config;
}

}  // namespace

DistributedSimulation::DistributedSimulation(const io::Config& config, Communicator comm)
    : config_(distributable(config)),
      end_time_(config.get<double>("time.end")),
      max_speed_(config.get<double>("time.max_speed")),
      grid_(run_grid(config)),
      fluid_(grid_, run_fluid_params(config), comm),
      coupler_(fluid_.decomposition(), delta_kernel(config.get<std::string>("coupling.kernel"))),
      membranes_(build_membrane_set(config, grid_)),
      stepper_(config.get<double>("time.dt"), config.get<double>("time.dt_min")) {
  std::vector<const ElasticMembrane*> ms;
  for (const auto& m : membranes_.membranes) ms.push_back(m.get());
  op_ = std::make_unique<DistributedOperator>(
      fluid_, coupler_, std::move(ms), membranes_.initial, membranes_.references,
      fluid_.scatter(run_initial_fluid_state(config_, grid_, fluid_.params())), run_contact_settings(config_),
      membranes_.viscosity_ratio);
  integrator_ = make_integrator(config_.get<std::string>("time.scheme"), run_solver_settings(config_),
                                comm.comm());
  integrator_->prepare(op_->size());
  start_budget();
}

FluidEnergy DistributedSimulation::fluid_energy() const {
  const SlabDecomposition& slabs = fluid_.decomposition();
  const Array3& chi = op_->viscosity_indicator();
  const PlaneRange cells = slabs.cells();
  const std::vector<double> mine =
      fluid_energy_planes(grid_, fluid_.params(), op_->fluid_state().u, chi.size() > 0 ? &chi : nullptr, cells.begin,
                          cells.end, slabs.offset());
  return fluid_energy_total(grid_, fluid_.params(), slabs.communicator().sum(mine));
}

std::vector<MembraneEnergy> DistributedSimulation::membrane_energies() const {
  // Each membrane's energies from its owner, zeros elsewhere: the sum over the processes is exact.
  const std::size_t M = num_membranes();
  std::vector<double> mine(3 * M, 0.0);
  std::string error;
  for (const OwnedMembrane& o : op_->ownership().owned()) {
    const auto m = static_cast<std::size_t>(o.id);
    try {
      const MembraneEnergy e = membrane_energy(*membranes_.membranes[m], o.positions);
      mine[3 * m] = e.elastic;
      mine[3 * m + 1] = e.bending;
      mine[3 * m + 2] = e.constraint;
    } catch (const SimulationError& e) {
      if (error.empty()) error = "membrane[" + std::to_string(m) + "] " + e.what();
    }
  }
  const Communicator& comm = fluid_.decomposition().communicator();
  if (const std::string first = first_error(comm, error); !first.empty()) throw SimulationError(first);
  const std::vector<double> all = comm.sum(mine);
  std::vector<MembraneEnergy> parts(M);
  for (std::size_t m = 0; m < M; ++m) parts[m] = {all[3 * m], all[3 * m + 1], all[3 * m + 2]};
  return parts;
}

void DistributedSimulation::start_budget() {
  const std::vector<MembraneEnergy> parts = membrane_energies();
  const FluidEnergy fluid = fluid_energy();
  budget_.start(total_energy(fluid.kinetic, parts), fluid);
}

bool DistributedSimulation::finished() const { return time() >= end_time_ * (1 - 1e-12); }

StepRecord DistributedSimulation::advance(const std::function<void(const std::string&)>& log) {
  const auto t0 = std::chrono::steady_clock::now();
  std::ostringstream where;
  where.precision(10);
  where << "step " << step_ + 1 << ", t = " << time() << ": ";
  const int migrated = op_->migrations();
  StepRecord r;
  try {
    const auto acc = stepper_.advance(*integrator_, *op_, end_time_ - time(), [&](const std::string& msg) {
      if (log) log(where.str() + msg);
    });
    r.stats = acc.stats;
    r.dt = acc.dt;
    r.rejected = acc.rejected;
    // The history moves with membranes that changed owner in the commit, then again in the volume correction
    // (follow() sends values the way the last migration sent the membranes).
    if (op_->migrations() != migrated) follow_history();
    const int corrected = op_->migrations();
    correct_volumes();
    if (op_->migrations() != corrected) follow_history();
  } catch (const SimulationError& e) {
    throw SimulationError(where.str() + e.what());
  }
  ++step_;
  r.step = step_;
  r.time = time();
  check_stability();
  budget_.advance(r.dt, fluid_energy());
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void DistributedSimulation::follow_history() {
  MembraneIntegrator& in = *integrator_;
  if (!(in.previous_dt() > 0)) return;  // no history yet (on every process alike)
  // X^{n-1}, then the stored guess errors, oldest first: arrays over the unknowns of the membranes owned before the
  // commit, moved with them.
  const std::size_t count = in.guess_errors().count();
  std::vector<double> before(in.previous_positions().begin(), in.previous_positions().end());
  const std::vector<double> errors = in.guess_errors().errors();
  before.insert(before.end(), errors.begin(), errors.end());
  const std::vector<double> now = op_->ownership().follow(before, 1 + count);
  const std::size_t n = op_->size();
  in.set_history(std::vector<double>(now.begin(), now.begin() + static_cast<std::ptrdiff_t>(n)), in.previous_dt(),
                 std::span<const double>(now).subspan(n), count);
}

void DistributedSimulation::correct_volumes() {
  // As Simulation after an accepted step: each owner shifts its membranes with volume_correction = "normal_shift"
  // back to their initial volume, then the node velocities are interpolated at the new positions.
  const auto& corrected = membranes_.corrected_volume;
  if (std::ranges::none_of(corrected, [](const auto& v) { return v.has_value(); })) return;
  const auto flat = op_->positions();
  std::vector<Vec3> X(flat.size() / 3);
  for (std::size_t i = 0; i < X.size(); ++i) X[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
  const auto offsets = op_->membrane_offsets();
  const auto& owned = op_->ownership().owned();
  std::string error;
  std::vector<Vec3> Xm;
  for (std::size_t k = 0; k < owned.size() && error.empty(); ++k) {
    const auto m = static_cast<std::size_t>(owned[k].id);
    if (!corrected[m]) continue;
    const auto first = X.begin() + static_cast<std::ptrdiff_t>(offsets[k] / 3),
               last = X.begin() + static_cast<std::ptrdiff_t>(offsets[k + 1] / 3);
    Xm.assign(first, last);
    try {
      normal_shift(membranes_.meshes[m], Xm, *corrected[m]);
    } catch (const SimulationError& e) {
      error = "membrane[" + std::to_string(m) + "] " + e.what();
    }
    std::copy(Xm.begin(), Xm.end(), first);
  }
  const Communicator& comm = fluid_.decomposition().communicator();
  if (comm.sum(error.empty() ? 0.0 : 1.0) > 0)
    throw SimulationError(error.empty() ? std::string("the volume correction of another process failed") : error);
  op_->correct_positions(X);
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
    const std::string prev = "fluid.u_prev" + std::to_string(d);
    if (ck.has(prev)) {
      if (f.u_prev[d].size() != f.u[d].size()) f.u_prev[d] = f.u[d];
      f.u_prev[d].values() = entries.array(prev, n);
    }
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
  const double dt = continued_step(config_, ck);
  const std::int64_t successes = entries.count("stepper.successes");
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
                                              fluid_.scatter(f), run_contact_settings(config_),
                                              membranes_.viscosity_ratio);
  integrator_->prepare(op_->size());
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
  integrator_->set_history(owned_part(prev_X), prev_dt, owned_part(guess_errors),
                           guess_errors.size() / std::max<std::size_t>(unknowns, 1));
  stepper_.set_state(dt, static_cast<int>(successes));
  step_ = step;
  if (!budget_.restore(ck)) start_budget();
}

}  // namespace immerse
