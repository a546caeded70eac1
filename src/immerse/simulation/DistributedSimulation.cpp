#include "immerse/simulation/DistributedSimulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/io/CellFields.hpp"
#include "immerse/io/ParallelCheckpoint.hpp"
#include "immerse/io/ParallelHdf5.hpp"
#include "immerse/membrane/VolumeCorrection.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/simulation/CheckpointEntries.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/simulation/StabilityCheck.hpp"

namespace immerse {

namespace {

/// The configuration, refused (InputError) where it asks for what is not distributed yet.
const io::Config& distributable(const io::Config& config) {
  if (config.get<std::string>("time.scheme") == "bfgs")
    throw InputError("time.scheme = \"bfgs\": the dense quasi-Newton matrix of eq. (35) is not distributed (use "
                     "\"jfnk\", \"anderson\" or \"lbfgs\", or run in one process)");
  return config;
}

/// The stop query of every process agreed: true on all when it is true on any. Collective in each call.
std::function<bool()> agreed(const Communicator& comm, const std::function<bool()>& stop_requested) {
  if (!stop_requested) return {};
  return [comm, stop_requested] { return max_over_processes(comm, stop_requested() ? 1 : 0) > 0; };
}

}  // namespace

DistributedSimulation::DistributedSimulation(const io::Config& config, Communicator comm,
                                             const StopQuery& stop_requested)
    : config_(distributable(config)),
      end_time_(config.get<double>("time.end")),
      max_speed_(config.get<double>("time.max_speed")),
      grid_(run_grid(config)),
      threads_(ThreadGovernor::from_environment()),
      fluid_(grid_, run_fluid_params(config), comm, run_fft_planning(config)),
      coupler_(fluid_.decomposition(), delta_kernel(config.get<std::string>("coupling.kernel"))),
      membranes_(build_membrane_set(config, grid_, fluid_.params().walls, agreed(comm, stop_requested))),
      stepper_(config.get<double>("time.dt"), config.get<double>("time.dt_min")) {
  std::vector<const ElasticMembrane*> ms;
  for (const auto& m : membranes_.membranes) ms.push_back(m.get());
  op_ = std::make_unique<DistributedOperator>(
      fluid_, coupler_, std::move(ms), membranes_.initial, membranes_.references,
      fluid_.scatter(run_initial_fluid_state(config_, grid_, fluid_.params())),
      run_contact_settings(config_, fluid_.params().walls),
      membranes_.viscosity_ratio);
  op_->set_thread_governor(threads_);
  integrator_ = make_integrator(config_.get<std::string>("time.scheme"), run_solver_settings(config_),
                                comm.comm());
  integrator_->prepare(op_->size());
  start_budget();
}

FluidEnergy DistributedSimulation::fluid_energy() const {
  const SlabDecomposition& slabs = fluid_.decomposition();
  const Array3& chi = op_->viscosity_indicator();
  const PlaneRange cells = slabs.cells();
  const FluidParams params = step_params(fluid_.params(), op_->fluid_state());
  const std::vector<double> mine = fluid_energy_planes(grid_, params, op_->fluid_state().u,
                                                       chi.size() > 0 ? &chi : nullptr, cells.begin, cells.end,
                                                       slabs.offset());
  return fluid_energy_total(grid_, params, slabs.communicator().sum(mine));
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

StepRecord DistributedSimulation::advance(const Log& log, const StopQuery& stop_requested) {
  const auto t0 = std::chrono::steady_clock::now();
  std::ostringstream where;
  where.precision(10);
  where << "step " << step_ + 1 << ", t = " << time() << ": ";
  const int migrated = op_->migrations();
  // fluid.flow_rate: the step's body work is taken with the step's own added force at both of its ends.
  const int flow_axis = fluid_.params().flow_axis;
  const double flow_momentum =
      flow_axis >= 0 ? mean_velocity(flow_axis) * grid_.length(0) * grid_.length(1) * grid_.length(2) : 0.0;
  const double flow_force = op_->fluid_state().flow_force;
  StepRecord r;
  try {
    const auto acc = stepper_.advance(
        *integrator_, *op_, end_time_ - time(),
        [&](const std::string& msg) {
          if (log) log(where.str() + msg);
        },
        agreed(communicator(), stop_requested));
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
  if (flow_axis >= 0) budget_.add_body_power((op_->fluid_state().flow_force - flow_force) * flow_momentum);
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
  // Simulation's check on this process's part: its owned nodes, then the planes of the fluid it holds.
  const StepPlace at{step_, time()};
  const auto X = op_->positions();
  const auto U = op_->node_velocity();
  const auto offsets = op_->membrane_offsets();
  std::string what;
  for (std::size_t k = 0; k + 1 < offsets.size() && what.empty(); ++k)
    for (std::size_t i = offsets[k]; i + 2 < offsets[k + 1] && what.empty(); i += 3)
      what = node_instability(at, op_->ownership().owned()[k].id, (i - offsets[k]) / 3, {X[i], X[i + 1], X[i + 2]},
                              {U[i], U[i + 1], U[i + 2]}, max_speed_);
  const SlabDecomposition& slabs = fluid_.decomposition();
  std::array<std::array<int, 2>, 4> planes{};
  for (int l = 0; l < 4; ++l) {
    const PlaneRange held = slabs.held(static_cast<Layout>(l));
    planes[l] = {held.begin - slabs.offset(), held.end - slabs.offset()};
  }
  if (what.empty()) what = fluid_instability(at, op_->fluid_state(), planes, slabs.offset(), max_speed_);
  // Every process stops with the message of the lowest-ranked process that found the run unstable.
  if (const std::string first = first_error(slabs.communicator(), what); !first.empty()) throw SimulationError(first);
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
  if (ck.has("fluid.flow_force")) f.flow_force = ck.get_double("fluid.flow_force");
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
                                              fluid_.scatter(f), run_contact_settings(config_, fluid_.params().walls),
                                              membranes_.viscosity_ratio);
  op_->set_thread_governor(threads_);
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

namespace {

/// Node offsets of the membranes in the global concatenation (global membrane order), and of their triangles.
struct GlobalLayout {
  std::vector<std::size_t> node, triangle;  ///< M + 1 entries each

  explicit GlobalLayout(const MembraneSet& set) : node{0}, triangle{0} {
    for (std::size_t m = 0; m < set.meshes.size(); ++m) {
      node.push_back(node.back() + set.references[m].size());
      triangle.push_back(triangle.back() + set.meshes[m].elements.size());
    }
  }
};

/// The z planes [begin, end) of the global array of `layout` this process holds, and their values in its slab.
std::span<const double> held_values(const SlabDecomposition& slabs, const Array3& local, Layout layout,
                                    PlaneRange& planes) {
  planes = slabs.held(layout);
  const std::size_t plane = static_cast<std::size_t>(local.nx()) * local.ny();
  return {local.data() + local.index(0, 0, planes.begin - slabs.offset()), plane * planes.count()};
}

}  // namespace

void DistributedSimulation::write_checkpoint(const std::filesystem::path& file, const Attributes& attributes,
                                             const std::function<void(io::Checkpoint&)>& extra) const {
  const DistributedSimulation& sim = *this;
  const SlabDecomposition& slabs = sim.fluid().decomposition();
  const Communicator& comm = slabs.communicator();
  io::ParallelCheckpoint ck(comm);
  ck.put_string("config", sim.config().to_toml_string());
  ck.put_int("step", sim.step());
  const FluidState& f = sim.op().fluid_state();
  const auto put_field = [&](const std::string& name, const Array3& local, Layout layout) {
    PlaneRange planes;
    const auto values = held_values(slabs, local, layout, planes);
    const auto s =
        layout == Layout::Pressure ? sim.grid().cell_shape() : sim.grid().face_shape(static_cast<int>(layout));
    const std::size_t plane = std::size_t(s[0]) * std::size_t(s[1]);
    ck.put_array(name, {std::size_t(s[2]), std::size_t(s[1]), std::size_t(s[0])},
                 {{planes.begin * plane, {values.begin(), values.end()}}});
  };
  for (int d = 0; d < 3; ++d) {
    put_field("fluid.u" + std::to_string(d), f.u[d], velocity_layout(d));
    put_field("fluid.adv" + std::to_string(d), f.adv[d], velocity_layout(d));
    // u^{n-1} of a variable viscosity, as in one process (a slab array on every process alike, or on none).
    if (f.u_prev[d].size() == f.u[d].size())
      put_field("fluid.u_prev" + std::to_string(d), f.u_prev[d], velocity_layout(d));
  }
  put_field("fluid.p", f.p, Layout::Pressure);
  put_field("fluid.p_prev", f.p_prev, Layout::Pressure);
  ck.put_double("fluid.dt_prev", f.dt_prev);
  ck.put_double("fluid.dt_prev2", f.dt_prev2);
  if (f.flow_force != 0) ck.put_double("fluid.flow_force", f.flow_force);  // with fluid.flow_rate
  ck.put_int("fluid.step", f.step);
  ck.put_double("fluid.time", f.time);
  const auto& owned = sim.op().ownership().owned();
  const auto flat = [](const std::vector<Vec3>& v) { return std::vector<double>(&v[0].x, &v[0].x + 3 * v.size()); };
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const std::string name = "membrane[" + std::to_string(m) + "]";
    const std::size_t n = sim.membranes().references[m].size();
    std::vector<io::ParallelCheckpoint::Piece> X, R;
    for (const OwnedMembrane& o : owned)
      if (static_cast<std::size_t>(o.id) == m) {
        X.push_back({0, flat(o.positions)});
        R.push_back({0, flat(o.reference)});
      }
    ck.put_array(name + ".positions", {n, 3}, std::move(X));
    ck.put_array(name + ".reference", {n, 3}, std::move(R));
  }
  // The integrator's history, per node in global membrane order: vectors of all unknowns one after the other.
  const GlobalLayout layout(sim.membranes());
  const std::size_t unknowns = 3 * layout.node.back();
  const std::size_t local = 3 * sim.op().ownership().num_owned_nodes();
  const auto put_history = [&](const std::string& name, const std::vector<double>& values) {
    const int vectors = max_over_processes(comm, local > 0 ? static_cast<int>(values.size() / local) : 0);
    std::vector<io::ParallelCheckpoint::Piece> pieces;
    std::size_t at = 0;
    for (int k = 0; k < vectors && local > 0; ++k)
      for (const OwnedMembrane& o : owned) {
        const std::size_t n = 3 * o.positions.size();
        pieces.push_back(
            {k * unknowns + 3 * layout.node[static_cast<std::size_t>(o.id)],
             {values.begin() + static_cast<std::ptrdiff_t>(at), values.begin() + static_cast<std::ptrdiff_t>(at + n)}});
        at += n;
      }
    ck.put_array(name, {static_cast<std::size_t>(vectors) * unknowns}, std::move(pieces));
  };
  put_history("integrator.previous_positions", sim.integrator().previous_positions());
  ck.put_double("integrator.previous_dt", sim.integrator().previous_dt());
  put_history("integrator.guess_errors", sim.integrator().guess_errors().errors());
  ck.put_double("stepper.dt", sim.stepper().dt());
  ck.put_int("stepper.successes", sim.stepper().successes());
  for (const auto& [name, value] : sim.energy_budget().entries()) ck.put_double(name, value);
  if (extra) {
    io::Checkpoint more;
    extra(more);
    if (more.checksum() != io::Checkpoint().checksum())
      throw std::logic_error("DistributedSimulation::write_checkpoint: a scenario's own entries are not distributed");
  }
  ck.set_attributes(attributes);
  ck.write(file);
}

void DistributedSimulation::write_frame(io::XdmfWriter* series, const std::filesystem::path& dir, int frame,
                                       const Attributes& attributes, bool fluid_fields) const {
  const DistributedSimulation& sim = *this;
  const SlabDecomposition& slabs = sim.fluid().decomposition();
  const Communicator& comm = slabs.communicator();
  const MembraneSet& set = sim.membranes();
  const GlobalLayout layout(set);
  const auto& owned = sim.op().ownership().owned();
  const auto offsets = sim.op().membrane_offsets();
  const auto U = sim.op().node_velocity();
  // The owned membranes' rows, in ascending global order.
  std::vector<double> X, F, V, tau1, tau2;
  std::vector<std::int32_t> conn, id;
  std::vector<io::phdf5::Rows> node_rows, triangle_rows;
  std::string error;
  for (std::size_t k = 0; k < owned.size() && error.empty(); ++k) {
    const auto m = static_cast<std::size_t>(owned[k].id);
    const auto& Xm = owned[k].positions;
    std::vector<Vec3> Fm;
    try {
      set.membranes[m]->compute_force(Xm, Fm);
      for (const auto& s : set.membranes[m]->node_strain(Xm)) tau1.push_back(s.tau1), tau2.push_back(s.tau2);
    } catch (const SimulationError& e) {
      error = "membrane[" + std::to_string(m) + "] " + e.what();
      break;
    }
    for (std::size_t i = 0; i < Xm.size(); ++i) {
      X.insert(X.end(), {Xm[i].x, Xm[i].y, Xm[i].z});
      F.insert(F.end(), {Fm[i].x, Fm[i].y, Fm[i].z});
    }
    V.insert(V.end(), U.begin() + static_cast<std::ptrdiff_t>(offsets[k]),
             U.begin() + static_cast<std::ptrdiff_t>(offsets[k + 1]));
    for (const auto& tri : set.meshes[m].elements)
      for (const int v : tri) conn.push_back(static_cast<std::int32_t>(layout.node[m]) + v);
    id.insert(id.end(), set.meshes[m].elements.size(), static_cast<std::int32_t>(m));
    node_rows.push_back({layout.node[m], Xm.size()});
    triangle_rows.push_back({layout.triangle[m], set.meshes[m].elements.size()});
  }
  if (const std::string first = first_error(comm, error); !first.empty()) throw SimulationError(first);

  const std::string file = io::XdmfWriter::frame_file_name(frame);
  const std::size_t M = sim.num_membranes(), nn = layout.node.back(), nt = layout.triangle.back();
  std::string names;
  for (std::size_t m = 0; m < M; ++m) names += (m ? " membrane" : "membrane") + std::to_string(m);
  const std::string mx = io::XdmfWriter::membranes_fragment(
      file, frame, sim.time(), names, nn, nt, {{"force", 3}, {"velocity", 3}, {"tension_1", 1}, {"tension_2", 1}});
  const std::string fx = fluid_fields ? io::XdmfWriter::fluid_fragment(file, frame, sim.time(), sim.grid()) : "";
  // The cell-centred velocity and vorticity need neighbouring planes: every process computes them on the gathered
  // velocity and writes its own cell planes.
  std::optional<io::CellFields> cells;
  if (fluid_fields) cells = io::CellFields::from_faces(sim.grid(), sim.fluid().gather(sim.op().fluid_state().u));
  const bool root = comm.rank() == 0;
  io::phdf5::write_file_atomically(dir / file, comm, [&](hid_t h5) {
    std::string failed;
    const auto check = [&](bool ok, const std::string& what) {
      if (!ok && failed.empty()) failed = "HDF5 error writing " + what;
    };
    check(io::hdf5::write_attribute(h5, "time", sim.time()), "time");
    for (const auto& [name, value] : attributes) check(io::hdf5::write_attribute(h5, name, value), name);
    {
      io::hdf5::Handle g = io::hdf5::create_group(h5, "membranes");
      check(g.valid() && io::hdf5::write_attribute(g.get(), "names", names), "/membranes");
      using io::phdf5::Rows;
      check(io::phdf5::write_doubles(g.get(), "nodes", {nn, 3}, node_rows, X.data()), "/membranes/nodes");
      check(io::phdf5::write_int32(g.get(), "connectivity", {nt, 6}, triangle_rows, conn.data()),
            "/membranes/connectivity");
      check(io::phdf5::write_int32(g.get(), "membrane_id", {nt}, triangle_rows, id.data()), "/membranes/membrane_id");
      std::vector<std::int64_t> node_offsets(layout.node.begin(), layout.node.end());
      const Rows all{0, node_offsets.size()};
      check(
          io::phdf5::write_int64(g.get(), "node_offsets", {node_offsets.size()},
                                 root ? std::span<const Rows>(&all, 1) : std::span<const Rows>(), node_offsets.data()),
          "/membranes/node_offsets");
      check(io::phdf5::write_doubles(g.get(), "force", {nn, 3}, node_rows, F.data()), "/membranes/force");
      check(io::phdf5::write_doubles(g.get(), "velocity", {nn, 3}, node_rows, V.data()), "/membranes/velocity");
      check(io::phdf5::write_doubles(g.get(), "tension_1", {nn}, node_rows, tau1.data()), "/membranes/tension_1");
      check(io::phdf5::write_doubles(g.get(), "tension_2", {nn}, node_rows, tau2.data()), "/membranes/tension_2");
      check(g.close(), "/membranes");
    }
    if (fluid_fields) {
      const auto& n = sim.grid().n();
      const PlaneRange z = slabs.cells();
      const std::size_t plane = std::size_t(n[0]) * std::size_t(n[1]), first = plane * std::size_t(z.begin);
      const std::size_t count = plane * std::size_t(z.count());
      std::vector<double> vel(3 * count);
      for (std::size_t c = 0; c < count; ++c)
        for (int d = 0; d < 3; ++d) vel[3 * c + d] = cells->velocity[d].data()[first + c];
      PlaneRange planes;
      const auto p = held_values(slabs, sim.op().fluid_state().p, Layout::Pressure, planes);
      const io::phdf5::Rows rows{hsize_t(z.begin), hsize_t(z.count())};
      const std::vector<hsize_t> sdims{hsize_t(n[2]), hsize_t(n[1]), hsize_t(n[0])};
      io::hdf5::Handle fg = io::hdf5::create_group(h5, "fluid");
      check(fg.valid(), "/fluid");
      check(io::phdf5::write_doubles(fg.get(), "velocity", {sdims[0], sdims[1], sdims[2], 3}, {&rows, 1}, vel.data()),
            "/fluid/velocity");
      check(io::phdf5::write_doubles(fg.get(), "pressure", sdims, {&rows, 1}, p.data()), "/fluid/pressure");
      check(io::phdf5::write_doubles(fg.get(), "vorticity_magnitude", sdims, {&rows, 1},
                                     cells->vorticity_magnitude.data() + first),
            "/fluid/vorticity_magnitude");
      check(fg.close(), "/fluid");
    }
    check(io::hdf5::write_attribute(h5, io::XdmfWriter::kMembranesAttribute, mx) &&
              io::hdf5::write_attribute(h5, io::XdmfWriter::kFluidAttribute, fx),
          "XDMF fragments");
    return failed;
  });
  // The series names the frame once every process has written it (rank 0 alone writes the XDMF files).
  std::string failed;
  if (series) try {
      series->append_frame(mx, fx);
    } catch (const WriteError& e) {
      failed = e.what();
    }
  if (const std::string first = first_error(comm, failed); !first.empty()) throw WriteError(first);
}

double DistributedSimulation::mean_velocity(int d) const {
  PlaneRange planes;
  const auto v = held_values(fluid_.decomposition(), op_->fluid_state().u[d], velocity_layout(d), planes);
  double sum = 0;
  for (double x : v) sum += x;
  const auto s = grid_.face_shape(d);
  return communicator().sum(sum) / (double(s[0]) * s[1] * s[2]);
}

double DistributedSimulation::wall_shear_stress(bool upper, double mu, double wall_velocity_x) const {
  const SlabDecomposition& slabs = fluid_.decomposition();
  const Array3& ux = op_->fluid_state().u[0];
  const Array3* chi = &op_->viscosity_indicator();
  double mine = 0;
  if (!upper && slabs.first()) mine = wall_shear_stress_sum(grid_, ux, chi, false, wall_velocity_x, 0 - slabs.offset());
  if (upper && slabs.last())
    mine = wall_shear_stress_sum(grid_, ux, chi, true, wall_velocity_x, grid_.n(2) - 1 - slabs.offset());
  return mu / (double(grid_.n(0)) * double(grid_.n(1))) * communicator().sum(mine);
}

double DistributedSimulation::min_wall_distance() const {
  const auto X = op_->positions();
  double mine = std::numeric_limits<double>::infinity();
  try {
    mine = immerse::min_wall_distance(grid_, {reinterpret_cast<const Vec3*>(X.data()), X.size() / 3});
  } catch (const SimulationError&) {
    mine = -1;  // a node outside the box: the next step reports it
  }
  const double all = min_over_processes(communicator(), mine);
  return all < 0 ? std::numeric_limits<double>::quiet_NaN() : all;
}

std::string DistributedSimulation::decomposition_summary() const {
  const SlabDecomposition& slabs = fluid_.decomposition();
  return "distributed over " + std::to_string(communicator().size()) + " MPI processes: slabs of " +
         std::to_string(slabs.block()) + " z planes of " + std::to_string(grid_.n(2));
}

std::string DistributedSimulation::thread_policy() const {
  return op_->thread_governor().policy() + " on each of " + std::to_string(communicator().size()) + " MPI processes";
}

std::string DistributedSimulation::thread_summary() const {
  return op_->thread_governor().summary() + " (rank 0 of " + std::to_string(communicator().size()) +
         " MPI processes, each choosing its own)";
}

void DistributedSimulation::set_applied_forces(std::size_t m, const std::vector<Vec3>& /*F*/) {
  throw InputError("membrane[" + std::to_string(m) + "]: applied nodal forces (scenario.kind = \"rbc_stretch\") are "
                   "not distributed over MPI processes (run it in one process)");
}

}  // namespace immerse
