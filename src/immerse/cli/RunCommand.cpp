#include "immerse/cli/RunCommand.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <memory>
#include <optional>
#include <streambuf>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/core/MemoryLimits.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/run/Diagnostics.hpp"
#include "immerse/run/MeshCopies.hpp"
#include "immerse/run/OutputSchedule.hpp"
#include "immerse/run/OutputWriter.hpp"
#include "immerse/run/StopSignals.hpp"
#include "immerse/run/TimeLoop.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/scenario/ScenarioRun.hpp"
#include "immerse/scenario/ShearPlaneProfile.hpp"
#include "immerse/simulation/DistributedSimulation.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

void check_run_paths(const CommandLine& options) {
  if (options.out.empty()) throw InputError("--out: an empty name was given: must name a folder");
  if (!options.restart.empty() && std::filesystem::is_directory(options.restart))
    throw InputError("--restart " + options.restart.string() + " is a folder: must name a checkpoint file (e.g. " +
                     (options.restart / "checkpoint.h5").string() + ")");
}

namespace {

std::string grid_text(const io::Config& c) {
  return "grid " + std::to_string(c.get<int>("grid.nx")) + " x " + std::to_string(c.get<int>("grid.ny")) + " x " +
         std::to_string(c.get<int>("grid.nz"));
}

/// A stream that drops what it is given: the log of the processes other than rank 0.
class NullBuffer : public std::streambuf {
 protected:
  int overflow(int c) override { return c; }
};

// A grid beyond the memory a process may use is refused before anything is allocated (the operating system would
// otherwise grant the memory and kill the run when it is touched). kBytesPerCell is a lower bound: the peak
// resident memory of a run grows by about 300 bytes per cell (16^3 -> 64^3, frames and checkpoints written; measured
// before the fast solvers tabulated their inverse symbols, 32 bytes per cell more). Over P processes each holds
// about 1/P of the cells.
void check_memory(const io::Config& c, int processes) {
  constexpr double kBytesPerCell = 250;
  const double cells = double(c.get<int>("grid.nx")) * c.get<int>("grid.ny") * c.get<int>("grid.nz");
  const auto limits = memory_limits();
  if (limits.empty()) return;
  const MemoryLimit& limit = *std::min_element(
      limits.begin(), limits.end(), [](const MemoryLimit& a, const MemoryLimit& b) { return a.bytes < b.bytes; });
  if (cells / processes * kBytesPerCell > limit.bytes) {
    std::ostringstream s;
    s << std::setprecision(3) << grid_text(c) << " = " << cells << " cells";
    if (processes > 1) s << " over " << processes << " processes";
    s << ": needs at least " << gigabytes(cells / processes * kBytesPerCell) << (processes > 1 ? " per process" : "")
      << ", more than " << limit.what;
    throw InputError(s.str());
  }
}

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

// One process: Simulation, with its threads; several: DistributedSimulation, the grid in slabs of z planes.
std::unique_ptr<SimulationInterface> build_simulation(const io::Config& config, const Communicator& world) {
  const int processes = world.size();
  check_memory(config, processes);
  const auto stop = [] { return StopSignals::received() != 0; };
  try {
    if (processes == 1) return std::make_unique<Simulation>(config, stop);
    check_process_count(config, processes);
    return std::make_unique<DistributedSimulation>(config, world, stop);
  } catch (const std::bad_alloc&) {
    throw InputError(grid_text(config) + ": the fluid and membrane arrays do not fit in this machine's memory");
  }
}

// The scenario binds to the simulation before a restart restores both. Returns false for a checkpoint without an
// energy budget (the budget's integrals then start at its state).
bool start_or_restore(SimulationInterface& sim, ScenarioRun& scenario, const std::filesystem::path& restart) {
  scenario.attach(sim);
  if (restart.empty()) {
    scenario.start(sim);
    return true;
  }
  const io::Checkpoint ck = io::Checkpoint::read(restart);
  sim.restore(ck);
  scenario.restore(ck, sim);
  return EnergyBudget::saved_in(ck);
}

/// The wall time of each part of the step: this process's, or over several the largest of any process.
StepTimings largest(const StepTimings& t, const Communicator& comm) {
  if (comm.size() == 1) return t;
  const auto most = [&](double x) { return -min_over_processes(comm, -x); };
  return {most(t.force), most(t.contact), most(t.spread), most(t.fluid), most(t.interpolate)};
}

// Collective: every process computes what rank 0 prints.
void print_summary(const SimulationInterface& sim, const TimeLoop& loop, int status, std::ostream& out) {
  const Communicator& comm = sim.communicator();
  const int processes = comm.size();
  out << "done: " << sim.step() << " steps, t = " << sim.time();
  if (status == 0)
    if (const double wall = sim.min_wall_distance(); std::isfinite(wall))
      out << ", closest approach of a node to a wall " << wall;
  out << "\n";
  if (max_over_processes(comm, loop.steps() > 0 ? 1 : 0) > 0) {
    std::ostringstream took;  // its own stream: the precision set here must not reach the lines below
    took << std::fixed << std::setprecision(1) << "stepping took " << loop.stepping_seconds() << " s";
    if (processes > 1)
      took << " on " << processes << " processes, " << sim.migrations() << " membranes changed process";
    out << took.str() << ", " << largest(loop.timings(), comm).profile(loop.stepping_seconds(), loop.steps());
    out << (processes > 1 ? " (each part the largest over the processes)\n" : "\n");
    out << sim.thread_summary() << "\n";
  }
  // The peak resident memory (VmHWM): over several processes the largest and the sum.
  const double peak = peak_resident_bytes().value_or(0.0);
  if (processes == 1) {
    if (peak > 0) out << "peak memory " << gigabytes(peak) << "\n";
  } else if (const double most = -min_over_processes(comm, -peak), total = comm.sum(peak); most > 0) {
    out << "peak memory " << gigabytes(most) << " on the largest process, " << gigabytes(total) << " in all\n";
  }
  const auto positions = sim.positions();
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const auto& X = positions[m];
    const auto g = measure(sim.mesh(m), X);
    const auto p = shear_plane_profile(sim.mesh(m), X, g.centroid);
    out << "membrane[" << m << "]: semi-axes " << g.semi_axes[0] << ", " << g.semi_axes[1] << ", " << g.semi_axes[2]
        << "  volume " << g.volume << "  Taylor deformation D_xz = " << p.D_xz << "  inclination theta = "
        << inclination(g) << " rad\n";
  }
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

int run_command(const CommandLine& options, std::ostream& out, std::ostream& err) {
  const Communicator world = Communicator::world();
  NullBuffer null_buffer;
  std::ostream null_stream(&null_buffer);
  std::ostream& log = world.rank() == 0 ? out : null_stream;
  std::ostream& errors = world.rank() == 0 ? err : null_stream;
  const auto refuse = [&](const std::string& error) {
    errors << "immerse: error: " << error << "\n";
    return 2;
  };
  StopSignals signals;
  // 1. Everything that can be wrong with the input is found, by every process, before anything is written.
  std::unique_ptr<SimulationInterface> sim;
  std::unique_ptr<ScenarioRun> scenario;
  std::optional<OutputSchedule> settings;
  std::optional<MeshCopies> copies;
  bool budget_continued = true, stopped = false;
  std::string error;
  try {
    check_run_paths(options);
    const io::ConfigSchema schema = run_schema();
    const io::Config config = apply_scenario(schema.parse_file(options.file, options.sets));
    settings = OutputSchedule::from(config);
    sim = build_simulation(config, world);
    scenario = make_scenario_run(config);
    budget_continued = start_or_restore(*sim, *scenario, options.restart);
    copies = MeshCopies::of(config, sim->fluid_params().walls.get());
  } catch (const InputError& e) {
    error = e.what();
  } catch (const StopRequested&) {  // while packing the cells (on every process): nothing has been written
    stopped = true;
  }
  if (stopped) {
    errors << "immerse: interrupted by signal " << max_over_processes(world, StopSignals::received())
           << " while packing the cells, before the first step; nothing written\n";
    return 4;
  }
  if (error = first_error(world, error); !error.empty()) return refuse(error);
  // 2. The output folder: may this run take it, and which rows of a run it continues stay (rank 0 decides).
  std::unique_ptr<OutputWriter> output;
  try {
    output = std::make_unique<OutputWriter>(options, *sim, *settings, *scenario);
  } catch (const InputError& e) {
    error = e.what();
  }
  if (error = first_error(world, error); !error.empty()) return refuse(error);
  if (const std::string warning = ThreadGovernor::oversubscription_warning(); !warning.empty())
    errors << "immerse: warning: " << warning << std::endl;
  // 3. The first files, then the time loop with its output on schedules.
  try {
    output->create(*copies, log);
  } catch (const InputError& e) {  // on every process: a folder this run created is removed again
    return refuse(e.what());
  }
  if (!budget_continued) log << energy_budget_note(options.restart, sim->step(), sim->time()) << std::flush;
  scenario->announce(log);
  TimeLoop loop(*sim, *scenario, *output, *settings, log, errors);
  const int status = loop.run();
  print_summary(*sim, loop, status, log);
  return status;
}

}  // namespace immerse
