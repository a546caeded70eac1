#include "immerse/app/RunCommand.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "immerse/app/Callback.hpp"
#include "immerse/app/Diagnostics.hpp"
#include "immerse/app/Scenario.hpp"
#include "immerse/app/ShearPlaneProfile.hpp"
#include "immerse/app/StretchSweep.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/MemoryLimits.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/CsvWriter.hpp"
#include "immerse/io/OutputFolder.hpp"
#include "immerse/io/Provenance.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/io/XdmfWriter.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/simulation/RunSchema.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_signal(int sig) { g_stop_signal = sig; }

void write_frame(io::XdmfWriter& writer, const Simulation& sim) {
  std::vector<std::vector<Vec3>> X, U, F;
  std::vector<std::vector<double>> tau1, tau2;
  std::vector<io::SurfaceFrame> frames;
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    X.push_back(sim.op().membrane_positions(m));
    U.push_back(sim.op().membrane_velocities(m));
    F.emplace_back();
    sim.membrane(m).compute_force(X.back(), F.back());
    const auto strain = sim.membrane(m).node_strain(X.back());
    tau1.emplace_back();
    tau2.emplace_back();
    for (const auto& s : strain) tau1.back().push_back(s.tau1), tau2.back().push_back(s.tau2);
  }
  for (std::size_t m = 0; m < sim.num_membranes(); ++m)
    frames.push_back({"membrane" + std::to_string(m),
                      X[m],
                      sim.mesh(m).elements,
                      {{"force", F[m]}, {"velocity", U[m]}},
                      {{"tension_1", tau1[m]}, {"tension_2", tau2[m]}}});
  const auto& f = sim.op().fluid_state();
  const io::FluidFrame fluid{sim.grid(), f.u, f.p};
  writer.write_frame(sim.time(), frames, sim.config().get<bool>("output.fluid_fields") ? &fluid : nullptr);
}

// The header and the data rows r = 0, 1, ... of a CSV file for which keep(r, first number of the row) holds (a
// restart continues after the checkpoint); nothing if the file does not exist. Reads only.
std::optional<std::string> rows_to_keep(const std::filesystem::path& path,
                                        const std::function<bool(long, double)>& keep) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::string line, kept;
  for (long r = -1; std::getline(in, line); ++r) {
    if (r >= 0) {
      char* end = nullptr;
      const double first = std::strtod(line.c_str(), &end);
      if (end == line.c_str() || (*end != ',' && *end != '\0'))
        throw InputError("cannot continue " + path.string() + ": line " + std::to_string(r + 2) +
                         " is not a row of numbers (damaged file)");
      if (!keep(r, first)) continue;
    }
    kept += line + "\n";
  }
  return kept;
}

// Signal dispositions while a run is on: SIGINT, SIGTERM, SIGHUP and SIGQUIT ask for a stop (checkpoint, exit 4);
// SIGPIPE is ignored, so that a closed standard output (`immerse run ... | head`) only silences the log. The
// previous dispositions come back at the end, unless a stop was asked for: then further stop signals (a storm of
// SIGTERM from a scheduler) keep only setting the flag until the program has exited with status 4.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      struct sigaction a {};
      a.sa_handler = kSignals[i] == SIGPIPE ? SIG_IGN : on_signal;
      a.sa_flags = SA_RESTART;
      sigemptyset(&a.sa_mask);
      sigaction(kSignals[i], &a, &saved_[i]);
    }
  }
  ~StopSignals() {
    if (g_stop_signal != 0) return;
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &saved_[i], nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  static constexpr std::array<int, 5> kSignals{SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE};
  std::array<struct sigaction, 5> saved_{};
};

const std::vector<Column> kStretchColumns{{"force_pN", "pN", "stretching force on each contact patch"},
                                          {"axial_um", "um", "steady diameter along the force (x)"},
                                          {"transverse_um", "um", "steady largest diameter across the force"}};

// "KEY = VALUE (how)" for every key a scenario kind derived, the membranes' keys as membrane[i].KEY.
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

bool same_folder(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a.parent_path().empty() ? "." : a.parent_path(), b, ec) && !ec;
}

class Progress {
 public:
  Progress(std::ostream& out, double end, double log_seconds)
      : out_(out), end_(end), every_(log_seconds), tty_(isatty(STDOUT_FILENO)), t0_(clock::now()), last_(t0_) {}
  void update(const Simulation& sim, long steps_done) {
    const auto now = clock::now();
    const double elapsed = std::chrono::duration<double>(now - t0_).count();
    if (!tty_ && std::chrono::duration<double>(now - last_).count() < every_) return;
    last_ = now;
    const double frac = std::min(1.0, sim.time() / end_), rate = double(steps_done) / std::max(elapsed, 1e-9);
    const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    std::ostringstream s;
    s << std::setprecision(4) << "t = " << sim.time() << " / " << end_ << "  step " << sim.step() << "  "
      << rate << " steps/s  ETA " << std::fixed << std::setprecision(0) << eta << " s";
    const double wall = sim.op().min_wall_distance();
    if (std::isfinite(wall)) s << std::scientific << std::setprecision(3) << "  closest wall approach " << wall;
    if (tty_) {
      const int width = 30, done = static_cast<int>(frac * width);
      out_ << "\r[" << std::string(done, '#') << std::string(width - done, '.') << "] " << s.str() << "   " << std::flush;
    } else {
      out_ << "progress: " << s.str() << "\n" << std::flush;
    }
  }
  void finish() {
    if (tty_) out_ << "\n";
  }

 private:
  using clock = std::chrono::steady_clock;
  std::ostream& out_;
  double end_, every_;
  bool tty_;
  clock::time_point t0_, last_;
};

std::string grid_text(const io::Config& c) {
  return "grid " + std::to_string(c.get<int>("grid.nx")) + " x " + std::to_string(c.get<int>("grid.ny")) + " x " +
         std::to_string(c.get<int>("grid.nz"));
}


// A grid beyond the memory the run may use is refused before anything is allocated (the operating system would
// otherwise grant the memory and kill the run when it is touched). kBytesPerCell is a lower bound: the peak
// resident memory of a run grows by about 300 bytes per cell (16^3 -> 64^3, frames and checkpoints written; measured
// before the fast solvers tabulated their inverse symbols, 32 bytes per cell more).
void check_memory(const io::Config& c) {
  constexpr double kBytesPerCell = 250;
  const double cells = double(c.get<int>("grid.nx")) * c.get<int>("grid.ny") * c.get<int>("grid.nz");
  const auto limits = memory_limits();
  if (limits.empty()) return;
  const MemoryLimit& limit = *std::min_element(
      limits.begin(), limits.end(), [](const MemoryLimit& a, const MemoryLimit& b) { return a.bytes < b.bytes; });
  if (cells * kBytesPerCell > limit.bytes) {
    std::ostringstream s;
    s << std::setprecision(3) << grid_text(c) << " = " << cells << " cells: needs at least "
      << gigabytes(cells * kBytesPerCell) << ", more than " << limit.what;
    throw InputError(s.str());
  }
}

// The mesh files of a run, to be copied into its folder, and the configuration naming the copies
// (mesh_membraneN.msh, mesh_membraneN_reference.msh, N the first membrane using the file), so that the folder runs
// again as it is. A file several membranes use is copied once.
struct MeshCopies {
  io::Config config;
  std::vector<std::pair<std::string, std::string>> files;  // name in the run folder, content
};

MeshCopies mesh_copies(const io::Config& config) {
  MeshCopies copies{config, {}};
  std::map<std::filesystem::path, std::string> copy_of;  // the source file -> the name of its copy
  for (std::size_t i = 0; i < config.count("membrane"); ++i)
    for (const std::string key : {"mesh.file", "mesh.reference_file"}) {
      const std::string k = "membrane[" + std::to_string(i) + "]." + key;
      const std::string source = config.get<std::string>(k);
      if (config.left_out(k) || source.empty()) continue;
      std::error_code ec;
      const std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(source), ec);
      const auto [it, added] = copy_of.emplace(
          full, "mesh_membrane" + std::to_string(i) + (key == "mesh.file" ? "" : "_reference") + ".msh");
      if (added) {
        std::ifstream in(source, std::ios::binary);
        std::ostringstream content;
        content << in.rdbuf();
        if (!in || ec) throw InputError(k + " " + source + ": cannot read the file to copy it into the run folder");
        copies.files.emplace_back(it->second, content.str());
      }
      copies.config.derive(k, io::format_toml(it->second), "the copy of " + full.string() + " in the run folder");
    }
  return copies;
}

}  // namespace

void print_config_help(std::ostream& out) { run_schema().print_help(out); }

void list_scenarios(const std::filesystem::path& dir, std::ostream& out) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(dir))
    for (const auto& e : std::filesystem::directory_iterator(dir))
      if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  out << "Bundled scenarios in " << dir.string() << " (run one with: immerse run FILE.toml):\n";
  for (const auto& f : files) {
    std::ifstream in(f);
    std::string first;
    std::getline(in, first);
    if (first.rfind("#", 0) == 0) first = first.substr(first.find_first_not_of("# "));
    out << "  " << std::left << std::setw(34) << f.filename().string() << first << "\n";
  }
}

int run_command(const RunOptions& options, std::ostream& out, std::ostream& err) {
  StopSignals signals;
  // 1. Everything that can be wrong with the input is found before anything is written.
  if (options.out.empty()) throw InputError("--out: an empty name was given: must name a folder");
  const bool restarted = !options.restart.empty();
  if (restarted && std::filesystem::is_directory(options.restart))
    throw InputError("--restart " + options.restart.string() + " is a folder: must name a checkpoint file (e.g. " +
                     (options.restart / "checkpoint.h5").string() + ")");
  const io::ConfigSchema schema = run_schema();
  const io::Config config = apply_scenario(schema.parse_file(options.file, options.sets));
  check_memory(config);
  std::unique_ptr<Simulation> built;
  try {
    built = std::make_unique<Simulation>(config);
  } catch (const std::bad_alloc&) {
    throw InputError(grid_text(config) + ": the fluid and membrane arrays do not fit in this machine's memory");
  }
  Simulation& sim = *built;
  std::unique_ptr<StretchSweep> sweep;
  if (is_sweep(config)) sweep = std::make_unique<StretchSweep>(sim);
  if (restarted) {
    const io::Checkpoint ck = io::Checkpoint::read(options.restart);
    sim.restore(ck);
    if (sweep) sweep->restore(ck, sim);
  } else if (sweep) {
    sweep->start(sim, 0);
  }
  const MeshCopies copies = mesh_copies(config);
  const int diagnostics_every = config.get<int>("output.diagnostics_every");
  const int fields_every = config.get<int>("output.fields_every");
  const int checkpoint_every = config.get<int>("output.checkpoint_every");

  // 2. The output folder belongs to this run: locked while it runs; one that holds another run is refused unless
  // this run continues it (--restart of its checkpoint) or replaces it (--overwrite). A restart into another
  // folder branches the run: a new series of rows, frames and checkpoints that begins at the checkpoint's step.
  const std::filesystem::path dir = options.out;
  const bool in_place = restarted && same_folder(options.restart, dir);
  if (in_place && options.overwrite)
    throw InputError("--overwrite: would remove the run that --restart " + options.restart.string() +
                     " continues (leave out --overwrite to continue it in " + dir.string() + ")");
  int first_frame = 0;
  if (in_place && fields_every > 0) first_frame = static_cast<int>(sim.step() / fields_every) + 1;
  io::OutputFolder folder(dir);
  if (const auto found = folder.run_files(); !found.empty() && !in_place && !options.overwrite) {
    std::string names;
    for (std::size_t i = 0; i < std::min<std::size_t>(found.size(), 3); ++i) names += (i ? ", " : "") + found[i];
    if (found.size() > 3) names += ", ...";
    throw InputError("--out " + dir.string() + " holds another run (" + names + "): choose another folder, " +
                     (restarted ? std::string("restart from that run's own checkpoint")
                                : "continue it with --restart " + (dir / "checkpoint.h5").string()) +
                     ", or replace it with --overwrite");
  }
  // A restart continues the tables after the checkpoint (a damaged table is refused before anything is rewritten).
  const auto column_info = diagnostics_column_info(config, sim.num_membranes());
  const auto columns = diagnostics_columns(config, sim.num_membranes());
  std::vector<std::string> stretch_columns;
  for (const auto& c : kStretchColumns) stretch_columns.push_back(c.name);
  std::optional<std::string> kept_diagnostics, kept_stretch;
  if (in_place) {
    io::CsvWriter::check_continuable(dir / "diagnostics.csv", columns);
    kept_diagnostics =
        rows_to_keep(dir / "diagnostics.csv", [&](long, double step) { return step <= double(sim.step()); });
    if (sweep) {
      io::CsvWriter::check_continuable(dir / "stretch.csv", stretch_columns);
      kept_stretch = rows_to_keep(dir / "stretch.csv", [&](long row, double) { return row < long(sweep->current()); });
    }
  }

  if (const std::string warning = ThreadGovernor::oversubscription_warning(); !warning.empty())
    err << "immerse: warning: " << warning << std::endl;

  // 3. Output. If its first files cannot be written, a folder this run created is removed again and an existing one
  // is put back as it was.
  io::Provenance provenance = io::Provenance::now(
      options.command_line.empty() ? "immerse run " + options.file.string() : options.command_line,
      sim.op().thread_governor().policy());
  if (restarted)
    provenance.restarted_from = options.restart.string() + " at step " + std::to_string(sim.step()) + ", t = " +
                                io::format_number(sim.time()) + (in_place ? " (continued)" : " (branched)");
  std::optional<io::XdmfWriter> frames_opt;
  std::optional<io::CsvWriter> csv_opt, stretch;
  folder.keep_run_files();  // until the first files are written: a failure leaves the folder as it was
  try {
    frames_opt.emplace(dir, first_frame);  // a restart reads back the frames before the checkpoint first
    frames_opt->set_attributes(provenance.attributes());
    if (options.overwrite) folder.remove_run_files();
    folder.remove_temporaries();  // of a writer that was killed
    if (kept_diagnostics) io::AtomicFile::write(dir / "diagnostics.csv", *kept_diagnostics);
    if (kept_stretch) io::AtomicFile::write(dir / "stretch.csv", *kept_stretch);

    out << "# immerse " << provenance.version << " (commit " << provenance.commit << "): " << options.file.string()
        << " -> " << dir.string() << "\n";
    for (const auto& line : derived_values(copies.config)) out << "# derived: " << line << "\n";
    if (!sim.packing_summary().empty()) out << "# " << sim.packing_summary() << "\n";
    if (options.verbose)
      out << "# resolved configuration (saved as config.resolved.toml)\n" << copies.config.to_toml_string();
    out << std::flush;
    io::AtomicFile::write(dir / "config.resolved.toml", provenance.toml_comments() + copies.config.to_toml_string());
    for (const auto& [name, content] : copies.files) io::AtomicFile::write(dir / name, content);
    io::AtomicFile::write(dir / "diagnostics.columns.csv", column_table(column_info));
    if (sweep) io::AtomicFile::write(dir / "stretch.columns.csv", column_table(kStretchColumns));

    const auto mode = in_place ? io::CsvWriter::Mode::Append : io::CsvWriter::Mode::Create;
    csv_opt.emplace(dir / "diagnostics.csv", columns, mode);
    if (sweep) stretch.emplace(dir / "stretch.csv", stretch_columns, mode);
  } catch (const WriteError&) {
    folder.restore_kept();
    throw;
  }
  folder.drop_kept();
  io::CsvWriter& csv = *csv_opt;
  io::XdmfWriter& frames = *frames_opt;
  if (sweep)
    out << "rbc_stretch: " << sweep->patch_nodes() << " nodes in the two contact patches, relaxation time "
        << sweep->relaxation_time() << " s\n";
  StepRecord last;  // the branch point of a restart into another folder is the first row of its series
  last.step = sim.step();
  last.time = sim.time();
  long checkpoint_step = -1;  // of the last checkpoint this run wrote

  std::vector<Callback> callbacks{
      // A row needs the record of its step: the step that turned out unstable has none.
      {"diagnostics", diagnostics_every, !in_place, true,
       [&](const Simulation& s) {
         if (last.step == s.step()) csv.row(diagnostics_row(s, last));
       }},
      {"fields", fields_every, !in_place && fields_every > 0, fields_every > 0,
       [&](const Simulation& s) { write_frame(frames, s); }},
      {"checkpoint", checkpoint_every, false, true,
       [&](const Simulation& s) {
         io::Checkpoint ck = s.checkpoint();
         if (sweep) sweep->save(ck);
         ck.set_attributes(provenance.attributes());
         ck.write(dir / "checkpoint.h5");
         checkpoint_step = s.step();
       }},
  };
  for (auto& c : callbacks)  // the restart step's row, frame and checkpoint exist (in place) or are not needed
    if (restarted && (in_place || !c.at_start)) c.last_step = sim.step();

  Progress progress(out, config.get<double>("time.end"), config.get<double>("output.log_seconds"));
  auto log = [&](const std::string& msg) { out << "\n" << msg << "\n" << std::flush; };
  int status = 0;
  long done = 0;
  double stepping = 0;  // wall time inside Simulation::advance, failed calls included
  const StepTimings timings_at_start = sim.op().timings();
  // rbc_stretch: once the cell is steady under a force, record its diameters and apply the next force, within the
  // step (before its callbacks), so that a checkpoint of this step already holds the next force.
  auto sweep_update = [&] {
    const bool steady = sweep->steady(sim);
    if (!steady && !sweep->timed_out(sim)) return;
    const double F = sweep->forces()[sweep->current()];
    if (!steady)
      log("force " + std::to_string(F * 1e12) + " pN: not steady after scenario.max_relaxation_times; recorded anyway");
    const CellDiameters d = cell_diameters(sim.op().membrane_positions(0), 0);
    stretch->row({F * 1e12, d.axial * 1e6, d.transverse * 1e6});
    out << "\nforce " << F * 1e12 << " pN: axial " << d.axial * 1e6 << " um, transverse " << d.transverse * 1e6
        << " um (t = " << sim.time() << " s)\n";
    sweep->start(sim, sweep->current() + 1);
  };
  auto step_once = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    const auto add_time = [&] {
      stepping += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    try {
      last = sim.advance(log, [] { return g_stop_signal != 0; });
    } catch (...) {
      add_time();
      throw;
    }
    add_time();
    ++done;
    if (sweep) sweep_update();
    for (auto& c : callbacks)
      if (c.due(sim.step())) c.run(sim, sim.step());
    progress.update(sim, done);
    if (g_stop_signal) status = 4;
  };
  // A full disk or a folder gone: no further write is attempted; what was written before is complete.
  auto write_failed = [&](const WriteError& e) {
    progress.finish();
    err << "immerse: run stopped at step " << sim.step() << ", t = " << sim.time() << ": " << e.what() << " ("
        << (checkpoint_step >= 0 ? "last checkpoint written: step " + std::to_string(checkpoint_step)
                                 : std::string("no checkpoint written"))
        << ")\n";
    status = 5;
  };
  try {
    for (auto& c : callbacks)
      if (c.at_start) c.run(sim, sim.step());
    if (g_stop_signal) status = 4;
    while (status == 0 && !sim.finished() && !(sweep && sweep->done())) step_once();
    if (status == 0 && sweep && !sweep->done())
      out << "\nrbc_stretch: time.end reached during force " << sweep->current() + 1 << " of " << sweep->forces().size()
          << " (" << sweep->forces()[sweep->current()] * 1e12 << " pN); continue the sweep with --restart "
          << (dir / "checkpoint.h5").string() << " and a later time.end\n";
  } catch (const SimulationError& e) {
    progress.finish();
    err << "immerse: run stopped: " << e.what() << "\n";
    status = 3;
  } catch (const StopRequested&) {
    status = 4;  // while a rejected step was to be retried: the state is the last accepted step's
  } catch (const WriteError& e) {
    write_failed(e);
  } catch (const InputError&) {
    // Bad input that shows only once the run is on (a PETSc option no solver object used in the first solve): exit 2
    // as if found before writing, so this run's files go again; a restart in its checkpoint's folder keeps it.
    progress.finish();
    if (!in_place) folder.remove_run_files();
    throw;
  }
  progress.finish();
  // The last state is always saved, whatever ended the run (after an instability: the unstable state, for
  // inspection), unless writing is what failed; a failure to save it is a failed write too (exit 5).
  if (status != 5) try {
      for (auto& c : callbacks)
        if (c.at_end && c.last_step != sim.step()) c.run(sim, sim.step());
    } catch (const WriteError& e) {
      write_failed(e);
    }
  if (status == 4) err << "immerse: interrupted by signal " << g_stop_signal << " at step " << sim.step() << ", t = "
                       << sim.time() << "; checkpoint written to " << (dir / "checkpoint.h5").string() << "\n";

  out << "done: " << sim.step() << " steps, t = " << sim.time();
  if (status == 0)
    if (const double wall = sim.op().min_wall_distance(); std::isfinite(wall))
      out << ", closest approach of a node to a wall " << wall;
  out << "\n";
  if (done > 0) {
    std::ostringstream took;  // its own stream: the precision set here must not reach the lines below
    took << std::fixed << std::setprecision(1) << "stepping took " << stepping << " s, ";
    out << took.str() << sim.op().timings().since(timings_at_start).profile(stepping, done) << "\n";
    out << sim.op().thread_governor().summary() << "\n";
  }
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const auto X = sim.op().membrane_positions(m);
    const auto g = measure(sim.mesh(m), X);
    const auto p = shear_plane_profile(sim.mesh(m), X, g.centroid);
    out << "membrane[" << m << "]: semi-axes " << g.semi_axes[0] << ", " << g.semi_axes[1] << ", " << g.semi_axes[2]
        << "  volume " << g.volume << "  Taylor deformation D_xz = " << p.D_xz << "  inclination theta = "
        << inclination(g) << " rad\n";
  }
  return status;
}

}  // namespace immerse
