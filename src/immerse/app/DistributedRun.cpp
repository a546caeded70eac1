#include "immerse/app/DistributedRun.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "immerse/app/Diagnostics.hpp"
#include "immerse/app/MeshCopies.hpp"
#include "immerse/app/OutputTable.hpp"
#include "immerse/app/Progress.hpp"
#include "immerse/app/RunCommand.hpp"
#include "immerse/app/RunSettings.hpp"
#include "immerse/app/Scenario.hpp"
#include "immerse/app/ScenarioRun.hpp"
#include "immerse/app/ShearPlaneProfile.hpp"
#include "immerse/app/StopSignals.hpp"
#include "immerse/app/SuspensionShearRun.hpp"
#include "immerse/app/UnstableStop.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/MemoryLimits.hpp"
#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/CellFields.hpp"
#include "immerse/io/OutputFolder.hpp"
#include "immerse/io/ParallelCheckpoint.hpp"
#include "immerse/io/ParallelHdf5.hpp"
#include "immerse/io/Provenance.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/io/XdmfWriter.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/simulation/DistributedSimulation.hpp"
#include "immerse/simulation/RunSchema.hpp"

namespace immerse {

namespace {

/// A stream that drops what it is given: the log of the processes other than rank 0.
class NullBuffer : public std::streambuf {
 protected:
  int overflow(int c) override { return c; }
};

// The slabs: every process needs a cell plane of its own, the last one two between z walls (SlabDecomposition).
void check_process_count(const io::Config& config, int processes) {
  const int nz = config.get<int>("grid.nz");
  const int need = config.get<std::string>("boundary.z") == "wall" ? 2 : 1;
  const auto fits = [&](int p) {
    const int block = (nz + p - 1) / p;
    return nz - (p - 1) * block >= need;
  };
  if (fits(processes)) return;
  int most = 1;
  for (int p = 1; p <= nz; ++p)
    if (fits(p)) most = p;
  throw InputError("grid.nz = " + std::to_string(nz) + ": " + std::to_string(processes) +
                   " processes leave the last one without " +
                   (need == 2 ? "two cell planes (walls along z)" : "a cell plane") +
                   "; a run in slabs of z planes takes at most " + std::to_string(most) + " processes on this grid");
}

// The kinds whose diagnostics come from the membranes' positions and the fluid alone; the others need work between
// the steps or tables of their own that the distributed run does not have.
void check_scenario_kind(const io::Config& config, int processes) {
  const std::string kind = config.get<std::string>("scenario.kind");
  if (kind == "rbc_channel" || kind == "custom" || kind == "suspension_shear" || is_shear_kind(kind)) return;
  throw InputError("scenario.kind = \"" + kind + "\": a run over " + std::to_string(processes) +
                   " MPI processes takes \"rbc_channel\", \"suspension_shear\", \"custom\" and the shear kinds "
                   "(run this kind in one process)");
}

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

/// The checkpoint of the run's state: the entries of Simulation::checkpoint(), each process giving its planes and
/// its membranes. Collective.
io::ParallelCheckpoint checkpoint_of(const DistributedSimulation& sim) {
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
  return ck;
}

/// Writes frame `frame` of the ParaView series as the one-process run does (XdmfWriter's layout), each process its
/// membranes' nodes and triangles and its z planes of the fluid; returns the XDMF fragments. SimulationError on every
/// process if the forces of a membrane cannot be evaluated. Collective.
std::pair<std::string, std::string> write_frame(const DistributedSimulation& sim, const std::filesystem::path& dir,
                                                int frame,
                                                const std::vector<std::pair<std::string, std::string>>& attributes,
                                                bool fluid_fields) {
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
  return {mx, fx};
}

/// The mean fluid velocity along y over the box (the column mean_velocity of rbc_channel), from every process's
/// planes of u_y. Collective.
double mean_velocity_y(const DistributedSimulation& sim) {
  PlaneRange planes;
  const auto v = held_values(sim.fluid().decomposition(), sim.op().fluid_state().u[1], Layout::VelocityY, planes);
  double sum = 0;
  for (double x : v) sum += x;
  const auto s = sim.grid().face_shape(1);
  return sim.fluid().decomposition().communicator().sum(sum) / (double(s[0]) * s[1] * s[2]);
}

/// The mean shear stresses on the lower and the upper z wall (wall_shear_stress), each from the slab holding the cell
/// plane next to it, with χ of the last trial. Collective.
std::pair<double, double> wall_stresses(const DistributedSimulation& sim, const SuspensionShearRun& run) {
  const SlabDecomposition& slabs = sim.fluid().decomposition();
  const Grid& grid = sim.grid();
  const Array3& ux = sim.op().fluid_state().u[0];
  const Array3* chi = &sim.op().viscosity_indicator();
  const double lower =
      slabs.first() ? wall_shear_stress_sum(grid, ux, chi, false, run.lower_wall_velocity(), 0 - slabs.offset()) : 0;
  const double upper = slabs.last() ? wall_shear_stress_sum(grid, ux, chi, true, run.upper_wall_velocity(),
                                                            grid.n(2) - 1 - slabs.offset())
                                    : 0;
  const double scale = run.viscosity() / (double(grid.n(0)) * double(grid.n(1)));
  const Communicator& comm = slabs.communicator();
  return {scale * comm.sum(lower), scale * comm.sum(upper)};
}

/// The closest approach of a node to a wall over all processes (not finite: no walls, or a node outside the box).
/// Collective.
double wall_distance(const DistributedSimulation& sim) {
  const auto X = sim.op().positions();
  double mine = std::numeric_limits<double>::infinity();
  try {
    mine = min_wall_distance(sim.grid(), {reinterpret_cast<const Vec3*>(X.data()), X.size() / 3});
  } catch (const SimulationError&) {
    mine = -1;  // a node outside the box: the next step reports it
  }
  const double all = min_over_processes(sim.fluid().decomposition().communicator(), mine);
  return all < 0 ? std::numeric_limits<double>::quiet_NaN() : all;
}

bool same_folder(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a.parent_path().empty() ? "." : a.parent_path(), b, ec) && !ec;
}

// Derived values of the configuration for the header, as RunOutput prints them.
std::vector<std::string> derived_values(const io::Config& config) {
  std::vector<std::string> lines;
  const auto add = [&](const io::Config& c, const std::string& prefix) {
    for (const auto& k : c.schema().keys())
      if (const std::string how = c.derivation(k.key); !how.empty())
        lines.push_back(prefix + k.key + " = " + c.value_text(k.key) + " (" + how + ")");
  };
  add(config, "");
  for (const auto& t : config.schema().table_arrays())
    for (std::size_t i = 0; i < config.count(t.name); ++i)
      add(config.entry(t.name, i), t.name + "[" + std::to_string(i) + "].");
  return lines;
}

/// What rank 0 writes alone: the folder and its first files, the diagnostics table and the XDMF series (the rules
/// of RunOutput).
class RootOutput {
 public:
  RootOutput(const RunOptions& options, const DistributedSimulation& sim, const RunSettings& settings,
             const ScenarioRun& scenario)
      : options_(options),
        dir_(options.out),
        restarted_(!options.restart.empty()),
        in_place_(restarted_ && same_folder(options.restart, options.out)),
        first_frame_(in_place_ && settings.fields_every > 0 ? static_cast<int>(sim.step() / settings.fields_every) + 1
                                                            : 0),
        diagnostics_(sim.config(), sim.num_membranes(), scenario),
        table_("diagnostics", diagnostics_.columns(),
               [step = sim.step()](long, double s) { return s <= double(step); }) {
    if (in_place_ && options.overwrite)
      throw InputError("--overwrite: would remove the run that --restart " + options.restart.string() +
                       " continues (leave out --overwrite to continue it in " + options.out.string() + ")");
    folder_.emplace(dir_);
    if (const auto found = folder_->run_files(); !found.empty() && !in_place_ && !options.overwrite) {
      std::string names;
      for (std::size_t i = 0; i < std::min<std::size_t>(found.size(), 3); ++i) names += (i ? ", " : "") + found[i];
      if (found.size() > 3) names += ", ...";
      throw InputError("--out " + dir_.string() + " holds another run (" + names + "): choose another folder, " +
                       (restarted_ ? std::string("restart from that run's own checkpoint")
                                   : "continue it with --restart " + (dir_ / "checkpoint.h5").string()) +
                       ", or replace it with --overwrite");
    }
    if (in_place_) table_.read_kept_rows(dir_);
  }

  bool in_place() const { return in_place_; }
  bool restarted() const { return restarted_; }
  int first_frame() const { return first_frame_; }
  const Diagnostics& diagnostics() const { return diagnostics_; }
  OutputTable& table() { return table_; }
  io::XdmfWriter& frames() { return *frames_; }

  /// The first files, as RunOutput::create (a failure puts the folder back as it was).
  void create(const MeshCopies& copies, const io::Provenance& provenance, const DistributedSimulation& sim,
              int processes, std::ostream& out) {
    folder_->keep_run_files();
    try {
      frames_.emplace(dir_, first_frame_);
      if (options_.overwrite) folder_->remove_run_files();
      folder_->remove_temporaries();
      table_.write_kept_rows(dir_);
      out << "# immerse " << provenance.version << " (commit " << provenance.commit << "): " << options_.file.string()
          << " -> " << dir_.string() << "\n";
      for (const auto& line : derived_values(copies.config)) out << "# derived: " << line << "\n";
      if (!sim.membranes().packing_summary.empty()) out << "# " << sim.membranes().packing_summary << "\n";
      const auto& slabs = sim.fluid().decomposition();
      out << "# distributed over " << processes << " MPI processes: slabs of " << slabs.block() << " z planes of "
          << sim.grid().n()[2] << "\n";
      if (options_.verbose)
        out << "# resolved configuration (saved as config.resolved.toml)\n" << copies.config.to_toml_string();
      out << std::flush;
      io::AtomicFile::write(dir_ / "config.resolved.toml", provenance.toml_comments() + copies.config.to_toml_string());
      for (const auto& [name, content] : copies.files) io::AtomicFile::write(dir_ / name, content);
      table_.write_column_table(dir_);
      table_.open(dir_, in_place_ ? io::CsvWriter::Mode::Append : io::CsvWriter::Mode::Create);
    } catch (const WriteError&) {
      folder_->restore_kept();
      throw;
    }
    folder_->drop_kept();
  }

  /// After bad input found once the run was on: its files go again, unless it continues its folder.
  void discard() const {
    if (!in_place_) folder_->remove_run_files();
  }

 private:
  const RunOptions& options_;
  std::filesystem::path dir_;
  bool restarted_, in_place_;
  int first_frame_;
  Diagnostics diagnostics_;
  OutputTable table_;
  std::optional<io::OutputFolder> folder_;
  std::optional<io::XdmfWriter> frames_;
};

/// Scheduled output of the distributed run, as RunOutput::callbacks: every, at start, at end, last step run.
struct Schedule {
  long every = 0;
  bool at_start = false, at_end = false;
  long last_step = -1;
  bool due(long step) const { return every > 0 && step % every == 0; }
};

class DistributedLoop {
 public:
  DistributedLoop(DistributedSimulation& sim, const RunOptions& options, const RunSettings& settings,
                  const ScenarioRun& scenario, RootOutput* root, io::Provenance provenance, std::ostream& out,
                  std::ostream& err)
      : sim_(sim),
        comm_(sim.fluid().decomposition().communicator()),
        settings_(settings),
        scenario_(scenario),
        channel_(sim.config().get<std::string>("scenario.kind") == "rbc_channel"),
        shear_rate_(shear_rate(sim.config())),
        root_(root),
        provenance_(std::move(provenance)),
        options_(options),
        dir_(options.out),
        out_(out),
        err_(err),
        progress_(out, settings.end_time, settings.log_seconds) {
    const bool restarted = !options.restart.empty();
    const bool in_place = restarted && same_folder(options.restart, options.out);
    frame_ = in_place && settings.fields_every > 0 ? static_cast<int>(sim.step() / settings.fields_every) + 1 : 0;
    diagnostics_ = {settings.diagnostics_every, !in_place, true};
    fields_ = {settings.fields_every, !in_place && settings.fields_every > 0, settings.fields_every > 0};
    checkpoint_ = {settings.checkpoint_every, false, true};
    for (Schedule* s : {&diagnostics_, &fields_, &checkpoint_})
      if (restarted && (in_place || !s->at_start)) s->last_step = sim.step();
    last_.step = sim.step();
    last_.time = sim.time();
    if (restarted) kept_ = {options.restart, sim.step(), sim.time(), in_place};
  }

  int run() {
    try {
      for (auto [s, act] : actions())
        if (s->at_start) run_action(*s, act);
      if (stop_signal()) status_ = 4;
      while (status_ == 0 && !sim_.finished()) step_once();
    } catch (const SimulationError& e) {
      progress_.finish();
      err_ << "immerse: run stopped: " << e.what() << "\n";
      status_ = 3;
      unstable_ = true;
    } catch (const WriteError& e) {
      write_failed(e);
    }
    progress_.finish();
    // The last state is saved, as in one process (after an instability to unstable_state.h5, for inspection).
    if (status_ != 5) try {
        for (auto [s, act] : actions()) {
          if (!s->at_end || s->last_step == sim_.step()) continue;
          try {
            run_action(*s, act);
          } catch (const SimulationError& e) {
            err_ << "immerse: " << name(s) << " of step " << sim_.step() << " not written: " << e.what() << "\n";
            status_ = 3;
            unstable_ = true;
          }
        }
      } catch (const WriteError& e) {
        write_failed(e);
      }
    if (status_ == 3)
      err_ << unstable_stop_line(options_, sim_.config(), kept_, sim_.step(), unstable_written_, comm_.size());
    if (status_ == 4)
      err_ << "immerse: interrupted by signal " << signal_ << " at step " << sim_.step() << ", t = " << sim_.time()
           << "; checkpoint written to " << (dir_ / "checkpoint.h5").string() << "\n";
    return status_;
  }

  long steps() const { return steps_; }
  double stepping_seconds() const { return stepping_; }

 private:
  enum class Action { Diagnostics, Fields, Checkpoint };

  std::vector<std::pair<Schedule*, Action>> actions() {
    return {{&diagnostics_, Action::Diagnostics}, {&fields_, Action::Fields}, {&checkpoint_, Action::Checkpoint}};
  }
  const char* name(const Schedule* s) const {
    return s == &diagnostics_ ? "diagnostics" : s == &fields_ ? "fields" : "checkpoint";
  }

  void run_action(Schedule& s, Action a) {
    switch (a) {
      case Action::Diagnostics:
        write_row();
        break;
      case Action::Fields: {
        const auto [mx, fx] = write_frame(sim_, dir_, frame_, provenance_.attributes(), settings_.fluid_fields);
        on_root([&] { root_->frames().append_frame(mx, fx); });
        ++frame_;
        break;
      }
      case Action::Checkpoint: {
        io::ParallelCheckpoint ck = checkpoint_of(sim_);
        ck.set_attributes(provenance_.attributes());
        if (unstable_) {
          ck.write(unstable_state_file(dir_));
          unstable_written_ = true;
          break;
        }
        ck.write(dir_ / "checkpoint.h5");
        checkpoint_step_ = sim_.step();
        kept_ = {dir_ / "checkpoint.h5", sim_.step(), sim_.time(), true};
        // Newer than the unstable state of an attempt this run continues: that post-mortem file goes.
        if (!stale_unstable_removed_) on_root([&] {
            std::error_code ec;
            std::filesystem::remove(unstable_state_file(dir_), ec);
            if (ec) throw WriteError("cannot remove " + unstable_state_file(dir_).string() + ": " + ec.message());
          });
        stale_unstable_removed_ = true;
        break;
      }
    }
    s.last_step = sim_.step();
  }

  // A row needs the record of its step: the step that turned out unstable has none.
  void write_row() {
    if (last_.step != sim_.step()) return;
    const auto X = sim_.gather_positions();
    const double mean_velocity = channel_ ? mean_velocity_y(sim_) : 0;
    const auto* suspension = dynamic_cast<const SuspensionShearRun*>(&scenario_);
    const auto stresses = suspension ? wall_stresses(sim_, *suspension) : std::pair<double, double>{};
    const auto energies = sim_.membrane_energies();
    on_root([&] {
      std::vector<double> row{double(last_.step), last_.time};
      if (shear_rate_ > 0) row.push_back(shear_rate_ * last_.time);
      row.insert(row.end(), {last_.dt, double(last_.stats.newton_its), double(last_.stats.gmres_its),
                             double(last_.stats.fluid_solves), last_.stats.residual, last_.wall_seconds});
      double enclosed = 0;
      for (std::size_t m = 0; m < X.size(); ++m) {
        const MembraneGeometry g = measure(sim_.membranes().meshes[m], X[m]);
        enclosed += g.volume;
        const ShearPlaneProfile p = shear_plane_profile(sim_.membranes().meshes[m], X[m], g.centroid);
        const auto a = semi_axes_along_xyz(g);
        row.insert(row.end(), {g.volume, g.area, g.centroid.x, g.centroid.y, g.centroid.z, a[0], a[1], a[2], p.D_xz,
                               inclination(g),
                               least_area_ratio(sim_.membranes().meshes[m], X[m],
                                                sim_.membranes().membranes[m]->reference_element_areas())
                                   .ratio});
        scenario_.add_membrane_values(X[m], row);
      }
      if (channel_) row.push_back(mean_velocity);
      if (suspension) suspension->add_values(enclosed, stresses.first, stresses.second, row);
      add_energy_values(sim_.energy_budget(), energies, row);
      root_->table().row(row);
    });
  }

  // Work of rank 0 alone (the CSV table, the XDMF series): a write that fails there stops every process.
  template <class Work>
  void on_root(Work&& work) {
    std::string failed;
    if (root_) try {
        work();
      } catch (const WriteError& e) {
        failed = e.what();
      }
    if (const std::string first = first_error(comm_, failed); !first.empty()) throw WriteError(first);
  }

  void step_once() {
    const auto t0 = std::chrono::steady_clock::now();
    StepRecord r;
    try {
      // A rejected step (halved and retried) is reported as in one process, by rank 0.
      r = sim_.advance([this](const std::string& message) { out_ << "\n" << message << "\n" << std::flush; });
    } catch (...) {
      stepping_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      throw;
    }
    stepping_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    last_ = r;
    ++steps_;
    for (auto [s, act] : actions())
      if (s->due(sim_.step())) run_action(*s, act);
    const double wall = wall_distance(sim_);
    progress_.update(
        sim_.time(), sim_.step(), [wall] { return wall; }, steps_);
    if (stop_signal()) status_ = 4;
  }

  // Whether any process was asked to stop: every process takes the same decision after the same step.
  bool stop_signal() {
    signal_ = max_over_processes(comm_, StopSignals::received());
    return signal_ != 0;
  }

  void write_failed(const WriteError& e) {
    progress_.finish();
    err_ << "immerse: run stopped at step " << sim_.step() << ", t = " << sim_.time() << ": " << e.what() << " ("
         << (checkpoint_step_ >= 0 ? "last checkpoint written: step " + std::to_string(checkpoint_step_)
                                   : std::string("no checkpoint written"))
         << ")\n";
    status_ = 5;
  }

  DistributedSimulation& sim_;
  const Communicator& comm_;
  const RunSettings& settings_;
  const ScenarioRun& scenario_;
  bool channel_;
  double shear_rate_;
  RootOutput* root_;
  io::Provenance provenance_;
  const RunOptions& options_;
  std::filesystem::path dir_;
  std::ostream& out_;
  std::ostream& err_;
  Progress progress_;
  Schedule diagnostics_, fields_, checkpoint_;
  StepRecord last_;
  int frame_ = 0;
  int status_ = 0, signal_ = 0;
  long steps_ = 0, checkpoint_step_ = -1;
  double stepping_ = 0;
  KeptCheckpoint kept_;  ///< where the run can continue from (no file: start again)
  bool unstable_ = false, unstable_written_ = false, stale_unstable_removed_ = false;
};

/// The provenance of rank 0 (its host and start time), the same on every process: HDF5 attributes written
/// together must be equal.
io::Provenance shared_provenance(const Communicator& comm, const RunOptions& options, long step, double time,
                                 bool in_place, int processes) {
  io::Provenance p = io::Provenance::now(
      options.command_line.empty() ? "immerse run " + options.file.string() : options.command_line,
      std::to_string(processes) + " MPI processes, each with the OpenMP threads OMP_NUM_THREADS gives it");
  if (!options.restart.empty())
    p.restarted_from = options.restart.string() + " at step " + std::to_string(step) +
                       ", t = " + io::format_number(time) + (in_place ? " (continued)" : " (branched)");
  for (std::string* s : {&p.version, &p.commit, &p.command_line, &p.start_time, &p.host, &p.threads, &p.restarted_from})
    *s = broadcast_text(comm, *s);
  return p;
}

}  // namespace

int run_distributed(const RunOptions& options, std::ostream& out, std::ostream& err) {
  const Communicator comm = Communicator::world();
  const int processes = comm.size();
  const bool root = comm.rank() == 0;
  NullBuffer null_buffer;
  std::ostream null_stream(&null_buffer);
  std::ostream& log = root ? out : null_stream;
  std::ostream& errors = root ? err : null_stream;
  StopSignals signals;
  // 1. Every process reads and checks the whole input and builds the run; nothing is written yet.
  std::unique_ptr<DistributedSimulation> sim;
  std::unique_ptr<ScenarioRun> scenario;
  std::optional<MeshCopies> copies;
  std::optional<RunSettings> settings;
  bool budget_continued = true;
  std::string error;
  try {
    check_run_paths(options);
    const io::ConfigSchema schema = run_schema();
    const io::Config config = apply_scenario(schema.parse_file(options.file, options.sets));
    settings = RunSettings::from(config);
    check_scenario_kind(config, processes);
    check_process_count(config, processes);
    sim = std::make_unique<DistributedSimulation>(config, comm);
    scenario = make_scenario_run(config);
    if (!options.restart.empty()) {
      const io::Checkpoint ck = io::Checkpoint::read(options.restart);
      sim->restore(ck);
      budget_continued = EnergyBudget::saved_in(ck);
    }
    copies = MeshCopies::of(config);
  } catch (const InputError& e) {
    error = e.what();
  }
  if (error = first_error(comm, error); !error.empty()) {
    errors << "immerse: error: " << error << "\n";
    return 2;
  }
  // 2. Rank 0 takes the output folder and writes the first files; the others learn whether it could.
  std::unique_ptr<RootOutput> output;
  const bool in_place = !options.restart.empty() && same_folder(options.restart, options.out);
  const io::Provenance provenance = shared_provenance(comm, options, sim->step(), sim->time(), in_place, processes);
  if (root) try {
      output = std::make_unique<RootOutput>(options, *sim, *settings, *scenario);
      output->create(*copies, provenance, *sim, processes, log);
      if (!budget_continued) log << energy_budget_note(options.restart, sim->step(), sim->time()) << std::flush;
      if (const std::string warning = ThreadGovernor::oversubscription_warning(); !warning.empty())
        errors << "immerse: warning: " << warning << std::endl;
    } catch (const InputError& e) {
      error = e.what();
      output.reset();  // a folder it created is removed again
    }
  if (error = broadcast_text(comm, error); !error.empty()) {
    errors << "immerse: error: " << error << "\n";
    return 2;
  }
  // 3. The time loop, with its output on schedules.
  DistributedLoop loop(*sim, options, *settings, *scenario, output.get(), provenance, log, errors);
  const int status = loop.run();
  log << "done: " << sim->step() << " steps, t = " << sim->time();
  if (status == 0)
    if (const double wall = wall_distance(*sim); std::isfinite(wall))
      log << ", closest approach of a node to a wall " << wall;
  log << "\n";
  if (loop.steps() > 0) {
    std::ostringstream took;
    took << std::fixed << std::setprecision(1) << "stepping took " << loop.stepping_seconds() << " s on " << processes
         << " processes, " << sim->migrations() << " membranes changed process\n";
    log << took.str();
  }
  // The peak resident memory of each process (VmHWM), the largest and the sum over the processes.
  const double peak = peak_resident_bytes().value_or(0.0);
  const double largest = -min_over_processes(comm, -peak), total = comm.sum(peak);
  if (largest > 0)
    log << "peak memory " << gigabytes(largest) << " on the largest process, " << gigabytes(total) << " in all\n";
  return status;
}

}  // namespace immerse
