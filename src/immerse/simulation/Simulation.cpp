#include "immerse/simulation/Simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/membrane/VolumeCorrection.hpp"
#include "immerse/simulation/CheckpointEntries.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/simulation/MembraneSet.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/StabilityCheck.hpp"
#include "immerse/timestep/DenseBfgs.hpp"

namespace immerse {

Simulation::Simulation(const io::Config& config, const std::function<bool()>& stop_requested)
    : config_(config),
      end_time_(config.get<double>("time.end")),
      max_speed_(config.get<double>("time.max_speed")),
      grid_(run_grid(config)),
      threads_(ThreadGovernor::from_environment()),
      fluid_(grid_, run_fluid_params(config), run_fft_planning(config)),
      coupler_(grid_, delta_kernel(config.get<std::string>("coupling.kernel"))),
      stepper_(config.get<double>("time.dt"), config.get<double>("time.dt_min")) {
  MembraneSet set = build_membrane_set(config_, grid_, fluid_.params().walls, stop_requested);
  meshes_ = std::move(set.meshes);
  references_ = std::move(set.references);
  initial_ = std::move(set.initial);
  membranes_ = std::move(set.membranes);
  corrected_volume_ = std::move(set.corrected_volume);
  viscosity_ratio_ = std::move(set.viscosity_ratio);
  packing_summary_ = std::move(set.packing_summary);
  std::vector<const ElasticMembrane*> ms;
  for (auto& m : membranes_) ms.push_back(m.get());
  op_ = std::make_unique<ImmersedBoundaryOperator>(fluid_, coupler_, ms, initial_,
                                                   run_initial_fluid_state(config_, grid_, fluid_.params()),
                                                   run_contact_settings(config, fluid_.params().walls),
                                                   viscosity_ratio_);
  op_->set_thread_governor(threads_);
  integrator_ = make_integrator(config.get<std::string>("time.scheme"), run_solver_settings(config));
  if (integrator_->name() == "bfgs" && op_->size() > DenseBfgs::max_unknowns)
    throw InputError("time.scheme = \"bfgs\": the dense quasi-Newton matrix of eq. (35) is limited to " +
                     std::to_string(DenseBfgs::max_unknowns) + " unknowns and this run has " +
                     std::to_string(op_->size()) + " (use \"jfnk\", \"anderson\" or \"lbfgs\")");
  integrator_->prepare(op_->size());
  start_budget();
}

FluidEnergy Simulation::fluid_energy() const {
  if (const GhostCellWalls* walls = fluid_.walls())
    return walls->energy(step_params(fluid_.params(), op_->fluid_state()), op_->fluid_state().u);
  const Array3& chi = op_->viscosity_indicator();
  return immerse::fluid_energy(grid_, step_params(fluid_.params(), op_->fluid_state()), op_->fluid_state().u,
                               chi.size() > 0 ? &chi : nullptr);
}

MembraneEnergy Simulation::membrane_energy(std::size_t m) const {
  return immerse::membrane_energy(*membranes_[m], op_->membrane_positions(m));
}

void Simulation::start_budget() {
  const std::vector<MembraneEnergy> parts = membrane_energies();
  const FluidEnergy fluid = fluid_energy();
  budget_.start(total_energy(fluid.kinetic, parts), fluid);
}

bool Simulation::finished() const { return time() >= end_time_ * (1 - 1e-12); }

StepRecord Simulation::advance(const Log& log, const StopQuery& stop_requested) {
  const auto t0 = std::chrono::steady_clock::now();
  const double remaining = end_time_ - time();
  // fluid.flow_rate: the step's body work is taken with the step's own added force at both of its ends.
  const int flow_axis = fluid_.params().flow_axis;
  const double flow_momentum =
      flow_axis >= 0 ? mean_velocity(flow_axis) * grid_.length(0) * grid_.length(1) * grid_.length(2) : 0.0;
  const double flow_force = op_->fluid_state().flow_force;
  StepRecord r;
  std::ostringstream where;
  where.precision(10);
  where << "step " << step_ + 1 << ", t = " << time() << ": ";
  try {
    const auto acc = stepper_.advance(*integrator_, *op_, remaining,
                                      [&](const std::string& msg) { log(where.str() + msg); }, stop_requested);
    r.stats = acc.stats;
    r.dt = acc.dt;
    r.rejected = acc.rejected;
    for (std::size_t m = 0; m < corrected_volume_.size(); ++m) {
      if (!corrected_volume_[m]) continue;
      auto X = op_->membrane_positions(m);
      try {
        normal_shift(meshes_[m], X, *corrected_volume_[m]);
      } catch (const SimulationError& e) {
        throw SimulationError(membrane_name(m) + " " + e.what());
      }
      op_->correct_positions(m, X);
    }
  } catch (const SimulationError& e) {
    throw SimulationError(where.str() + e.what());
  }
  ++step_;
  r.step = step_;
  r.time = time();
  check_stability(r);
  if (flow_axis >= 0) budget_.add_body_power((op_->fluid_state().flow_force - flow_force) * flow_momentum);
  budget_.advance(r.dt, fluid_energy());
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void Simulation::check_stability(const StepRecord& r) const {
  const StepPlace at{r.step, r.time};
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto X = op_->membrane_positions(m);
    const auto U = op_->membrane_velocities(m);
    for (std::size_t i = 0; i < X.size(); ++i)
      if (const auto what = node_instability(at, m, i, X[i], U[i], max_speed_); !what.empty())
        throw SimulationError(what);
  }
  // The fluid everywhere in the box, also where no membrane samples it.
  const FluidState& f = op_->fluid_state();
  const std::array<std::array<int, 2>, 4> planes{
      {{0, f.u[0].nz()}, {0, f.u[1].nz()}, {0, f.u[2].nz()}, {0, f.p.nz()}}};
  if (const auto what = fluid_instability(at, f, planes, 0, max_speed_); !what.empty()) throw SimulationError(what);
}

io::Checkpoint Simulation::checkpoint() const {
  io::Checkpoint ck;
  ck.put_string("config", config_.to_toml_string());
  ck.put_int("step", step_);
  const FluidState& f = op_->fluid_state();
  for (int d = 0; d < 3; ++d) {
    const auto& u = f.u[d];
    const std::vector<std::size_t> shape{std::size_t(u.nz()), std::size_t(u.ny()), std::size_t(u.nx())};
    ck.put_array("fluid.u" + std::to_string(d), u.values(), shape);
    ck.put_array("fluid.adv" + std::to_string(d), f.adv[d].values(), shape);
    // u^{n-1}, which a variable viscosity extrapolates from (absent before the first step and without one).
    if (f.u_prev[d].size() == u.size()) ck.put_array("fluid.u_prev" + std::to_string(d), f.u_prev[d].values(), shape);
  }
  ck.put_array("fluid.p", f.p.values(), {std::size_t(f.p.nz()), std::size_t(f.p.ny()), std::size_t(f.p.nx())});
  ck.put_array("fluid.p_prev", f.p_prev.values(),
               {std::size_t(f.p_prev.nz()), std::size_t(f.p_prev.ny()), std::size_t(f.p_prev.nx())});
  ck.put_double("fluid.dt_prev", f.dt_prev);
  ck.put_double("fluid.dt_prev2", f.dt_prev2);
  if (f.flow_force != 0) ck.put_double("fluid.flow_force", f.flow_force);  // with fluid.flow_rate
  ck.put_int("fluid.step", f.step);
  ck.put_double("fluid.time", f.time);
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto X = op_->membrane_positions(m);
    ck.put_array(membrane_name(m) + ".positions", {&X[0].x, &X[0].x + 3 * X.size()}, {X.size(), 3});
    const auto& R = references_[m];
    ck.put_array(membrane_name(m) + ".reference", {&R[0].x, &R[0].x + 3 * R.size()}, {R.size(), 3});
  }
  ck.put_array("integrator.previous_positions", integrator_->previous_positions());
  ck.put_double("integrator.previous_dt", integrator_->previous_dt());
  ck.put_array("integrator.guess_errors", integrator_->guess_errors().errors());
  ck.put_double("stepper.dt", stepper_.dt());
  ck.put_int("stepper.successes", stepper_.successes());
  for (const auto& [name, value] : budget_.entries()) ck.put_double(name, value);
  return ck;
}

void Simulation::restore(const io::Checkpoint& ck) {
  check_checkpoint_configuration(config_, ck);
  const CheckpointEntries entries(ck);
  const auto count = [&](const std::string& name) { return entries.count(name); };
  const auto time_value = [&](const std::string& name) { return entries.time_value(name); };
  const auto array = [&](const std::string& name, std::size_t size) -> const std::vector<double>& {
    return entries.array(name, size);
  };
  FluidState f = fluid_.initial_state();
  for (int d = 0; d < 3; ++d) {
    const std::size_t n = f.u[d].values().size();
    f.u[d].values() = array("fluid.u" + std::to_string(d), n);
    f.adv[d].values() = array("fluid.adv" + std::to_string(d), n);
    const std::string prev = "fluid.u_prev" + std::to_string(d);
    if (ck.has(prev)) {
      if (f.u_prev[d].size() != n) f.u_prev[d] = f.u[d];
      f.u_prev[d].values() = array(prev, n);
    }
  }
  f.p.values() = array("fluid.p", f.p.values().size());
  f.dt_prev = time_value("fluid.dt_prev");
  // Checkpoints written before fluid.pressure have no p^{n-3/2}: an extrapolating run then lags for one step.
  if (ck.has("fluid.p_prev")) {
    f.p_prev.values() = array("fluid.p_prev", f.p_prev.values().size());
    f.dt_prev2 = time_value("fluid.dt_prev2");
  }
  f.step = count("fluid.step");
  f.time = time_value("fluid.time");
  if (ck.has("fluid.flow_force")) f.flow_force = ck.get_double("fluid.flow_force");
  std::vector<std::vector<Vec3>> X(num_membranes());
  std::size_t unknowns = 0;
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto& R = references_[m];
    if (ck.array(membrane_name(m) + ".reference") != std::vector<double>(&R[0].x, &R[0].x + 3 * R.size()))
      throw InputError("checkpoint: the reference state of " + membrane_name(m) +
                       " differs from the one this configuration builds (was its mesh file changed?)");
    const auto& a3 = array(membrane_name(m) + ".positions", 3 * R.size());
    X[m].resize(a3.size() / 3);
    for (std::size_t i = 0; i < X[m].size(); ++i) X[m][i] = {a3[3 * i], a3[3 * i + 1], a3[3 * i + 2]};
    unknowns += a3.size();
  }
  const std::string previous = "integrator.previous_positions";
  const auto& prev_X = array(previous, ck.array(previous).empty() ? 0 : unknowns);
  const double prev_dt = time_value("integrator.previous_dt");
  // Checkpoints written before the initial-guess recurrence have no guess errors: it then starts afresh.
  const std::string errors = "integrator.guess_errors";
  const std::vector<double> guess_errors =
      ck.has(errors) ? array(errors, ck.array(errors).size()) : std::vector<double>{};
  const double dt = continued_step(config_, ck);
  const std::int64_t successes = count("stepper.successes");
  const std::int64_t step = count("step");
  const double end = config_.get<double>("time.end");
  if (f.time >= end * (1 - 1e-12)) {
    std::ostringstream s;
    s << "time.end = " << end << ": must be later than the time of the checkpoint " << ck.source() << ", t = "
      << f.time << " (nothing left to run)";
    throw InputError(s.str());
  }
  std::vector<const ElasticMembrane*> ms;
  for (auto& m : membranes_) ms.push_back(m.get());
  op_ = std::make_unique<ImmersedBoundaryOperator>(fluid_, coupler_, ms, X, std::move(f),
                                                   run_contact_settings(config_, fluid_.params().walls),
                                                   viscosity_ratio_);
  integrator_->set_history(prev_X, prev_dt, guess_errors);
  stepper_.set_state(dt, static_cast<int>(successes));
  step_ = step;
  if (!budget_.restore(ck)) start_budget();
}

std::vector<std::vector<Vec3>> Simulation::positions() const {
  std::vector<std::vector<Vec3>> X;
  for (std::size_t m = 0; m < num_membranes(); ++m) X.push_back(op_->membrane_positions(m));
  return X;
}

std::vector<MembraneEnergy> Simulation::membrane_energies() const {
  std::vector<MembraneEnergy> parts;
  for (std::size_t m = 0; m < num_membranes(); ++m) parts.push_back(membrane_energy(m));
  return parts;
}

double Simulation::mean_velocity(int d) const {
  const auto& v = op_->fluid_state().u[d].values();
  double sum = 0;
  for (double x : v) sum += x;
  return sum / double(v.size());
}

double Simulation::wall_shear_stress(bool upper, double mu, double wall_velocity_x) const {
  return immerse::wall_shear_stress(grid_, op_->fluid_state().u, &op_->viscosity_indicator(), mu, upper,
                                    wall_velocity_x);
}

void Simulation::write_checkpoint(const std::filesystem::path& file, const Attributes& attributes,
                                  const std::function<void(io::Checkpoint&)>& extra) const {
  io::Checkpoint ck = checkpoint();
  if (extra) extra(ck);
  ck.set_attributes(attributes);
  ck.write(file);
}

void Simulation::write_frame(io::XdmfWriter* series, const std::filesystem::path& /*dir*/, int frame,
                             const Attributes& attributes, bool fluid_fields) const {
  if (!series || series->frames() != frame)
    throw std::logic_error("Simulation::write_frame: the series is not at frame " + std::to_string(frame));
  std::vector<std::vector<Vec3>> X, U, F;
  std::vector<std::vector<double>> tau1, tau2;
  std::vector<io::SurfaceFrame> frames;
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    X.push_back(op_->membrane_positions(m));
    U.push_back(op_->membrane_velocities(m));
    F.emplace_back();
    membrane(m).compute_force(X.back(), F.back());
    const auto strain = membrane(m).node_strain(X.back());
    tau1.emplace_back();
    tau2.emplace_back();
    for (const auto& s : strain) tau1.back().push_back(s.tau1), tau2.back().push_back(s.tau2);
  }
  for (std::size_t m = 0; m < num_membranes(); ++m)
    frames.push_back({"membrane" + std::to_string(m),
                      X[m],
                      mesh(m).elements,
                      {{"force", F[m]}, {"velocity", U[m]}},
                      {{"tension_1", tau1[m]}, {"tension_2", tau2[m]}}});
  const auto& f = op_->fluid_state();
  const io::FluidFrame fluid{grid_, f.u, f.p};
  series->set_attributes(attributes);
  series->write_frame(time(), frames, fluid_fields ? &fluid : nullptr);
}

}  // namespace immerse
