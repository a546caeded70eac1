#include "immerse/app/RunCommand.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

#include "immerse/app/Diagnostics.hpp"
#include "immerse/app/DistributedRun.hpp"
#include "immerse/app/MeshCopies.hpp"
#include "immerse/app/RunOutput.hpp"
#include "immerse/app/RunSettings.hpp"
#include "immerse/app/Scenario.hpp"
#include "immerse/app/ScenarioRun.hpp"
#include "immerse/app/ShearPlaneProfile.hpp"
#include "immerse/app/StopSignals.hpp"
#include "immerse/app/TimeLoop.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/MemoryLimits.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/simulation/RunSchema.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

void check_run_paths(const RunOptions& options) {
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

std::unique_ptr<Simulation> build_simulation(const io::Config& config) {
  check_memory(config);
  try {
    return std::make_unique<Simulation>(config, [] { return StopSignals::received() != 0; });
  } catch (const std::bad_alloc&) {
    throw InputError(grid_text(config) + ": the fluid and membrane arrays do not fit in this machine's memory");
  }
}

// The scenario binds to the simulation before a restart restores both. Returns false for a checkpoint without an
// energy budget (the budget's integrals then start at its state).
bool start_or_restore(Simulation& sim, ScenarioRun& scenario, const std::filesystem::path& restart) {
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

void print_summary(const Simulation& sim, const TimeLoop& loop, int status, std::ostream& out) {
  out << "done: " << sim.step() << " steps, t = " << sim.time();
  if (status == 0)
    if (const double wall = sim.op().min_wall_distance(); std::isfinite(wall))
      out << ", closest approach of a node to a wall " << wall;
  out << "\n";
  if (loop.steps() > 0) {
    std::ostringstream took;  // its own stream: the precision set here must not reach the lines below
    took << std::fixed << std::setprecision(1) << "stepping took " << loop.stepping_seconds() << " s, ";
    out << took.str() << loop.timings().profile(loop.stepping_seconds(), loop.steps()) << "\n";
    out << sim.op().thread_governor().summary() << "\n";
  }
  if (const auto peak = peak_resident_bytes()) out << "peak memory " << gigabytes(*peak) << "\n";
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const auto X = sim.op().membrane_positions(m);
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

int run_command(const RunOptions& options, std::ostream& out, std::ostream& err) {
  if (Communicator::world().size() > 1) return run_distributed(options, out, err);
  StopSignals signals;
  // 1. Everything that can be wrong with the input is found before anything is written.
  check_run_paths(options);
  const io::ConfigSchema schema = run_schema();
  const io::Config config = apply_scenario(schema.parse_file(options.file, options.sets));
  const RunSettings settings = RunSettings::from(config);
  std::unique_ptr<Simulation> sim;
  try {
    sim = build_simulation(config);
  } catch (const StopRequested&) {  // while packing the cells: nothing has been written
    err << "immerse: interrupted by signal " << StopSignals::received()
        << " while packing the cells, before the first step; nothing written\n";
    return 4;
  }
  const std::unique_ptr<ScenarioRun> scenario = make_scenario_run(config);
  const bool budget_continued = start_or_restore(*sim, *scenario, options.restart);
  const MeshCopies copies = MeshCopies::of(config);
  // 2. The output folder: may this run take it, and which rows of a run it continues stay.
  RunOutput output(options, *sim, settings, *scenario);
  if (const std::string warning = ThreadGovernor::oversubscription_warning(); !warning.empty())
    err << "immerse: warning: " << warning << std::endl;
  // 3. The first files, then the time loop with its output on schedules.
  output.create(copies, out);
  if (!budget_continued) out << energy_budget_note(options.restart, sim->step(), sim->time()) << std::flush;
  scenario->announce(out);
  TimeLoop loop(*sim, *scenario, output, settings, out, err);
  const int status = loop.run();
  print_summary(*sim, loop, status, out);
  return status;
}

}  // namespace immerse
