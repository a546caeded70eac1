// `immerse run` under mpiexec: the quick red-cell channel with midpoint RK2 written on 2 processes,
// continued on 3 and in one process, against the uninterrupted one-process run, and the same with Anderson, λ = 5
// cells and the volume correction; repeated runs bitwise; bad input on 3 processes; the ParaView frames written
// together by the processes.
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>

#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Hdf5.hpp"
#include "test_run_support.hpp"

namespace immerse::testing {
namespace {

/// Starts `mpiexec -n NP immerse ARGS...` with the environment OpenMPI needs to start as root without a remote
/// launcher; -q leaves the standard error to the program. One OpenMP thread per process, or with `governed` the
/// processes unbound and OMP_NUM_THREADS unset (each process's thread governor chooses). Returns the pid of mpiexec.
pid_t start_mpi(int np, const std::vector<std::string>& args, const fs::path& log_prefix, bool governed = false) {
  std::vector<std::string> argv_s{IMMERSE_MPIEXEC, "-q", "-n", std::to_string(np), "--oversubscribe"};
  if (governed) argv_s.insert(argv_s.end(), {"--bind-to", "none"});
  argv_s.push_back(immerse_program().string());
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s{"OMPI_ALLOW_RUN_AS_ROOT=1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1",
                                 "OMPI_MCA_plm=isolated", "OMPI_MCA_btl_vader_single_copy_mechanism=none",
                                 "OMP_NUM_THREADS=1", "ASAN_OPTIONS=detect_leaks=0"};
  for (char** e = environ; *e; ++e) {
    const std::string v = *e;
    if (std::none_of(env_s.begin(), env_s.end(), [&](const std::string& s) {
          return v.rfind(s.substr(0, s.find('=') + 1), 0) == 0;
        }))
      env_s.push_back(v);
  }
  if (governed) std::erase(env_s, std::string("OMP_NUM_THREADS=1"));
  std::vector<char*> envp;
  for (auto& v : env_s) envp.push_back(v.data());
  envp.push_back(nullptr);
  const std::string out = log_prefix.string() + ".stdout", err = log_prefix.string() + ".stderr";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + argv_s[0]);
  return pid;
}

RunResult wait_mpi(pid_t pid, const fs::path& log_prefix) {
  int st = 0;
  waitpid(pid, &st, 0);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st), read_text(log_prefix.string() + ".stdout"),
          read_text(log_prefix.string() + ".stderr")};
}

/// `mpiexec -n NP immerse ARGS...` to its end.
RunResult run_mpi(int np, const std::vector<std::string>& args, const fs::path& log_prefix, bool governed = false) {
  return wait_mpi(start_mpi(np, args, log_prefix, governed), log_prefix);
}

/// The processes whose parent is `parent` (the ranks started by mpiexec).
std::vector<pid_t> children(pid_t parent) {
  std::vector<pid_t> found;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string stat = read_text(e.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 2));
    char state = 0;
    pid_t ppid = 0;
    if (rest >> state >> ppid && ppid == parent) found.push_back(std::stoi(e.path().filename().string()));
  }
  return found;
}

// The quick channel with midpoint RK2 at dt = 2e-5 s (ParallelRun's step), a frame and a checkpoint every 3 steps.
std::vector<std::string> channel_args(const fs::path& out, int steps, const fs::path& restart = {}) {
  return run_args(scenario_file("rbc_channel_quick.toml"), out,
                  {"time.scheme=rk2", "time.dt=2e-5", "time.end=" + std::to_string(2e-5 * steps),
                   "output.fields_every=3", "output.checkpoint_every=3"},
                  restart);
}

std::vector<double> positions(const io::Checkpoint& ck) {
  std::vector<double> all;
  for (int m = 0; ck.has("membrane[" + std::to_string(m) + "].positions"); ++m) {
    const auto& a = ck.array("membrane[" + std::to_string(m) + "].positions");
    all.insert(all.end(), a.begin(), a.end());
  }
  return all;
}

/// The cells of a CSV file of numbers and names, by row.
std::vector<std::vector<std::string>> read_csv(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);) {
    rows.emplace_back();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) rows.back().push_back(cell);
  }
  return rows;
}

/// max |a - b| / max |b|.
double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0, scale = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    d = std::max(d, std::abs(a[i] - b[i]));
    scale = std::max(scale, std::abs(b[i]));
  }
  return d / scale;
}

std::vector<std::string> entry_names(const io::Checkpoint& ck, const io::Checkpoint& other) {
  std::vector<std::string> missing;
  for (const char* name :
       {"config", "step", "fluid.u0", "fluid.u1", "fluid.u2", "fluid.adv0", "fluid.adv1", "fluid.adv2", "fluid.p",
        "fluid.p_prev", "fluid.dt_prev", "fluid.dt_prev2", "fluid.step", "fluid.time", "membrane[0].positions",
        "membrane[31].reference", "integrator.previous_positions", "integrator.previous_dt",
        "integrator.guess_errors", "stepper.dt", "stepper.successes"})
    if (!ck.has(name) || !other.has(name)) missing.push_back(name);
  return missing;
}

TEST(RunMpi, CheckpointOfTwoProcessesContinuesOnThreeAndInOneProcessAsTheUninterruptedRun) {
  // 2 processes to step 3, then 3 processes (and one) to step 6, against one process to step 6.
  ScratchDir dir("run_mpi");
  const auto one = run_mpi(1, channel_args(dir / "one", 6), dir / "one");
  ASSERT_EQ(one.status, 0) << one.err;
  const auto two = run_mpi(2, channel_args(dir / "two", 3), dir / "two");
  ASSERT_EQ(two.status, 0) << two.err;
  EXPECT_NE(two.out.find("distributed over 2 MPI processes"), std::string::npos) << two.out;
  const auto three = run_mpi(3, channel_args(dir / "three", 6, dir / "two" / "checkpoint.h5"), dir / "three");
  ASSERT_EQ(three.status, 0) << three.err;
  EXPECT_EQ(three.err, "");
  const auto serial = run_mpi(1, channel_args(dir / "serial", 6, dir / "two" / "checkpoint.h5"), dir / "serial");
  ASSERT_EQ(serial.status, 0) << serial.err;

  const io::Checkpoint reference = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  const io::Checkpoint half = io::Checkpoint::read(dir / "two" / "checkpoint.h5");
  const io::Checkpoint continued = io::Checkpoint::read(dir / "three" / "checkpoint.h5");
  const io::Checkpoint continued_serially = io::Checkpoint::read(dir / "serial" / "checkpoint.h5");
  EXPECT_EQ(entry_names(half, reference), std::vector<std::string>{});
  EXPECT_EQ(half.get_int("step"), 3);
  EXPECT_EQ(reference.get_int("step"), 6);
  EXPECT_EQ(continued.get_int("step"), 6);
  EXPECT_EQ(continued_serially.get_int("step"), 6);
  EXPECT_DOUBLE_EQ(continued.get_double("fluid.time"), reference.get_double("fluid.time"));
  // The membranes moved by about 4e-8 m in 6 steps: 1e-10 of the largest coordinate (4.8e-5 m) is far below that.
  const auto X = positions(reference);
  ASSERT_EQ(X.size(), 32u * 642u * 3u);
  EXPECT_LT(relative_difference(positions(continued), X), 1e-10);
  EXPECT_LT(relative_difference(positions(continued_serially), X), 1e-10);
  EXPECT_GT(relative_difference(positions(half), X), 1e-6);  // the cells moved between steps 3 and 6
  for (const char* u : {"fluid.u0", "fluid.u1", "fluid.u2"})
    EXPECT_LT(relative_difference(continued.array(u), reference.array(u)), 1e-10) << u;
  // The other way: the one-process checkpoint of step 6 continued on 2 processes and in one, to step 9.
  const auto on_two = run_mpi(2, channel_args(dir / "on_two", 9, dir / "one" / "checkpoint.h5"), dir / "on_two");
  ASSERT_EQ(on_two.status, 0) << on_two.err;
  const auto on_one = run_mpi(1, channel_args(dir / "on_one", 9, dir / "one" / "checkpoint.h5"), dir / "on_one");
  ASSERT_EQ(on_one.status, 0) << on_one.err;
  const io::Checkpoint nine_two = io::Checkpoint::read(dir / "on_two" / "checkpoint.h5");
  const io::Checkpoint nine_one = io::Checkpoint::read(dir / "on_one" / "checkpoint.h5");
  EXPECT_EQ(nine_two.get_int("step"), 9);
  EXPECT_LT(relative_difference(positions(nine_two), positions(nine_one)), 1e-10);
  std::printf("[RunMpi] step 9 from the one-process checkpoint of step 6, 2 processes against one: positions %.2g\n",
              relative_difference(positions(nine_two), positions(nine_one)));
  std::printf("[RunMpi] step 6 after 2 + 3 processes, after 2 + 1 process, against one process: positions %.2g, %.2g, "
              "u_y %.2g\n",
              relative_difference(positions(continued), X), relative_difference(positions(continued_serially), X),
              relative_difference(continued.array("fluid.u1"), reference.array("fluid.u1")));
  // The distributed diagnostics have the one-process columns, and their row of step 3 the same values of what does
  // not depend on round-off in the last digits of nearly vanishing numbers (theta of a flat cell, say, or the energy
  // budget's residual, a difference of nearly equal energies): the energy columns among them.
  const auto one_rows = read_csv(dir / "one" / "diagnostics.csv");
  const auto two_rows = read_csv(dir / "two" / "diagnostics.csv");
  ASSERT_EQ(one_rows.size(), 8u);  // header, steps 0 to 6
  ASSERT_EQ(two_rows.size(), 5u);  // header, steps 0 to 3
  EXPECT_EQ(one_rows[0], two_rows[0]);
  int compared = 0;
  for (std::size_t c = 0; c < one_rows[0].size(); ++c) {
    const std::string& name = one_rows[0][c];
    const auto ends_with = [&](const std::string& tail) { return name.ends_with(tail); };
    if (!(name == "step" || name == "time" || name == "dt" || name == "fluid_solves" || name == "mean_velocity" ||
          name == "flow_rate" || name == "pressure_drop" || name == "relative_viscosity" ||
          ends_with("volume") || ends_with("area") || ends_with("cx") || ends_with("cy") || ends_with("cz") ||
          name == "E_kinetic" || name == "dissipation" || name == "P_walls" || name == "P_body" || name == "E_total" ||
          ends_with("E_elastic") || ends_with("E_bending") || ends_with("E_constraint")))
      continue;
    const double a = std::stod(two_rows[4][c]), b = std::stod(one_rows[4][c]);
    EXPECT_LE(std::abs(a - b), 1e-10 * std::abs(b)) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 4 + 5 * 32 + 4 + 5 + 3 * 32);
}

// Anderson at a tolerance that makes every step iterate, with λ = 5 cells whose volume the normal shift restores:
// the checkpoint carries the integrator's history (X^{n-1}, the guess errors, per node in global order), u^{n-1} of
// the variable viscosity and the step control, which a restart on another process count hands to the new owners.
// Δt = 2^-16 s makes every step time exact, so no step is shortened to meet time.end (a shortened step would start
// the guess errors afresh) and the interrupted run takes the uninterrupted one's steps.
std::vector<std::string> implicit_args(const fs::path& out, int steps, const fs::path& restart = {}) {
  const double dt = std::ldexp(1.0, -16);
  char end[32];
  std::snprintf(end, sizeof end, "%.17g", steps * dt);
  return run_args(scenario_file("rbc_channel_quick.toml"), out,
                  {"time.scheme=anderson", "solver.newton_rtol=1e-11", "time.dt=1.52587890625e-05",
                   std::string("time.end=") + end, "membrane[0].viscosity_ratio=5.0",
                   "membrane[0].volume_correction=\"normal_shift\"", "output.fields_every=0",
                   "output.checkpoint_every=3"},
                  restart);
}

TEST(RunMpi, ImplicitRunWithViscosityContrastContinuesOnAnotherProcessCountAsTheUninterruptedRun) {
  ScratchDir dir("run_mpi");
  const auto one = run_mpi(1, implicit_args(dir / "one", 6), dir / "one");
  ASSERT_EQ(one.status, 0) << one.err;
  const auto two = run_mpi(2, implicit_args(dir / "two", 3), dir / "two");
  ASSERT_EQ(two.status, 0) << two.err;
  const auto three = run_mpi(3, implicit_args(dir / "three", 6, dir / "two" / "checkpoint.h5"), dir / "three");
  ASSERT_EQ(three.status, 0) << three.err;
  const io::Checkpoint reference = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  const io::Checkpoint half = io::Checkpoint::read(dir / "two" / "checkpoint.h5");
  const io::Checkpoint continued = io::Checkpoint::read(dir / "three" / "checkpoint.h5");
  EXPECT_EQ(continued.get_int("step"), 6);
  // The history is there: X^{n-1} of every unknown and at least one stored guess error.
  const std::size_t unknowns = 32u * 642u * 3u;
  EXPECT_EQ(half.array("integrator.previous_positions").size(), unknowns);
  EXPECT_GE(half.array("integrator.guess_errors").size(), unknowns);
  EXPECT_EQ(half.array("integrator.guess_errors").size() % unknowns, 0u);
  EXPECT_EQ(half.get_double("stepper.dt"), std::ldexp(1.0, -16));
  EXPECT_TRUE(half.has("fluid.u_prev1"));
  // Every step iterates and the continued run takes the one-process iterations (the diagnostics' solver columns;
  // the restarted series starts with the row of the checkpoint's state).
  const auto one_rows = read_csv(dir / "one" / "diagnostics.csv");
  const auto three_rows = read_csv(dir / "three" / "diagnostics.csv");
  ASSERT_EQ(one_rows.size(), 8u);  // header, steps 0 to 6
  ASSERT_EQ(three_rows[0], one_rows[0]);
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(one_rows[0].begin(), one_rows[0].end(), name) - one_rows[0].begin());
  };
  const std::size_t newton = column("newton_its"), solves = column("fluid_solves");
  ASSERT_LT(std::max(newton, solves), one_rows[0].size());
  int compared = 0;
  for (std::size_t row = 1; row < three_rows.size(); ++row) {
    const int step = std::stoi(three_rows[row][0]);
    if (step <= 3) continue;
    ASSERT_LE(step, 6);
    const auto& expected = one_rows[static_cast<std::size_t>(step) + 1];
    EXPECT_GT(std::stoi(expected[newton]), 0) << "step " << step;
    EXPECT_EQ(three_rows[row][newton], expected[newton]) << "step " << step;
    EXPECT_EQ(three_rows[row][solves], expected[solves]) << "step " << step;
    ++compared;
  }
  EXPECT_EQ(compared, 3);
  const double dX = relative_difference(positions(continued), positions(reference));
  const double du = relative_difference(continued.array("fluid.u1"), reference.array("fluid.u1"));
  std::printf("[RunMpi] Anderson, λ = 5, normal shift: step 6 after 2 + 3 processes against one process: positions "
              "%.2g, u_y %.2g\n",
              dX, du);
  EXPECT_LT(dX, 1e-10);
  EXPECT_LT(du, 1e-10);
  EXPECT_LT(relative_difference(continued.array("integrator.guess_errors"), reference.array("integrator.guess_errors")),
            1e-6);
  EXPECT_GT(relative_difference(positions(half), positions(reference)), 1e-6);
}

// The suspension between sliding walls (λ = 5 cells packed to H = 0.2, contact, the volume correction, JFNK; cells of
// 642 nodes without the area dilation energy, contact within one grid spacing, to keep it short): its
// run columns (volume fraction, the two wall stresses with χ, relative viscosity) from the first and the last slab.
TEST(RunMpi, SuspensionShearOnThreeProcessesWritesTheOneProcessViscosity) {
  ScratchDir dir("run_mpi");
  const auto args = [&](const fs::path& out) {
    return run_args(scenario_file("suspension_shear_quick.toml"), out,
                    {"time.end=2e-4", "membrane[0].mesh.level=2", "membrane[0].dilation_modulus=0",
                     "contact.range=7.5e-7", "packing.clearance=0", "output.fields_every=0",
                     "output.checkpoint_every=0"});
  };
  const auto one = run_mpi(1, args(dir / "one"), dir / "one");
  ASSERT_EQ(one.status, 0) << one.err;
  const auto three = run_mpi(3, args(dir / "three"), dir / "three");
  ASSERT_EQ(three.status, 0) << three.err;
  const auto a = read_csv(dir / "one" / "diagnostics.csv");
  const auto b = read_csv(dir / "three" / "diagnostics.csv");
  ASSERT_EQ(a.size(), 4u);  // header, steps 0 to 2
  ASSERT_EQ(b.size(), a.size());
  ASSERT_EQ(b[0], a[0]);
  double largest = 0;
  for (const char* name : {"volume_fraction", "wall_stress_lower", "wall_stress_upper", "relative_viscosity"}) {
    const auto c = static_cast<std::size_t>(std::find(a[0].begin(), a[0].end(), name) - a[0].begin());
    ASSERT_LT(c, a[0].size()) << name;
    for (std::size_t row = 1; row < a.size(); ++row) {
      const double x = std::stod(b[row][c]), y = std::stod(a[row][c]);
      EXPECT_LE(std::abs(x - y), 1e-10 * std::abs(y)) << name << " at step " << row - 1;
      largest = std::max(largest, std::abs(x - y) / std::abs(y));
    }
  }
  const auto viscosity = static_cast<std::size_t>(
      std::find(a[0].begin(), a[0].end(), "relative_viscosity") - a[0].begin());
  EXPECT_GT(std::stod(a[3][viscosity]), 1.0);  // the cells raise the wall stress
  std::printf("[RunMpi] suspension_shear, 3 processes against one: relative viscosity at step 2 %s, largest relative "
              "difference of the run columns %.2g\n",
              b[3][viscosity].c_str(), largest);
}

TEST(RunMpi, TwoProcessRunsGiveBitwiseTheSameCheckpoint) {
  ScratchDir dir("run_mpi");
  const auto a = run_mpi(2, channel_args(dir / "a", 3), dir / "a");
  const auto b = run_mpi(2, channel_args(dir / "b", 3), dir / "b");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const io::Checkpoint ca = io::Checkpoint::read(dir / "a" / "checkpoint.h5");
  const io::Checkpoint cb = io::Checkpoint::read(dir / "b" / "checkpoint.h5");
  EXPECT_TRUE(ca == cb);
  EXPECT_EQ(ca.checksum(), cb.checksum());
  EXPECT_EQ(ca.get_int("step"), 3);
}

/// Exactly one line on the standard error, the error line, exit status 2 and no output folder.
void expect_refused(const RunResult& r, const fs::path& out, const std::string& text) {
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RunMpi, BadInputOnThreeProcessesIsOneLineAndWritesNothing) {
  ScratchDir dir("run_mpi");
  auto args = channel_args(dir / "bad_key", 3);
  args.insert(args.end(), {"--set", "time.bogus=1"});
  expect_refused(run_mpi(3, args, dir / "bad_key"), dir / "bad_key", "time.bogus");
  // 24 cells between z walls: at most 2 processes leave two planes to the last one when there are only 4.
  args = channel_args(dir / "planes", 3);
  args.insert(args.end(), {"--set", "grid.nz=4"});
  expect_refused(run_mpi(3, args, dir / "planes"), dir / "planes", "grid.nz = 4: 3 processes");
  args = channel_args(dir / "dense", 3);
  args.insert(args.end(), {"--set", "time.scheme=bfgs"});
  expect_refused(run_mpi(3, args, dir / "dense"), dir / "dense", "time.scheme = \"bfgs\"");
  args = run_args(scenario_file("rbc_stretch.toml"), dir / "kind", {"time.scheme=rk2"});
  expect_refused(run_mpi(3, args, dir / "kind"), dir / "kind", "scenario.kind = \"rbc_stretch\"");
  args = run_args(scenario_file("tube_flow.toml"), dir / "walls",
                  {"domain.Lz=6e-6", "grid.nz=12", "wall[0].center=[5e-6,5e-6,3e-6]"});
  expect_refused(run_mpi(3, args, dir / "walls"), dir / "walls", "[[wall]]: must be absent in a run on several");
}

TEST(RunMpi, CheckpointOfAnotherGridAndTheFolderOfAnotherRunAreRefusedOnThreeProcesses) {
  ScratchDir dir("run_mpi");
  // A checkpoint of another grid (the same channel at twice the resolution).
  ASSERT_EQ(run_mpi(2, channel_args(dir / "two", 3), dir / "two").status, 0);
  auto args = channel_args(dir / "other_grid", 6, dir / "two" / "checkpoint.h5");
  args.insert(args.end(), {"--set", "grid.nx=96", "--set", "grid.ny=192", "--set", "grid.nz=48"});
  expect_refused(run_mpi(3, args, dir / "other_grid"), dir / "other_grid", "grid.nx = 96: the checkpoint");
  // The folder of another run.
  const auto again = run_mpi(3, channel_args(dir / "two", 3), dir / "again");
  EXPECT_EQ(again.status, 2);
  EXPECT_EQ(std::count(again.err.begin(), again.err.end(), '\n'), 1) << again.err;
  EXPECT_NE(again.err.find("holds another run"), std::string::npos) << again.err;
}

TEST(RunMpi, FramesWrittenTogetherHoldTheDatasetsTheXdmfNames) {
  ScratchDir dir("run_mpi");
  const auto r = run_mpi(3, channel_args(dir / "run", 3), dir / "run");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* series : {"membranes.xdmf", "fluid.xdmf"}) {
    const std::string xdmf = read_text(dir / "run" / series);
    const std::regex item(R"re(<DataItem Dimensions="([0-9 ]+)"[^>]*Format="HDF">([^:<]+):([^<]+)</DataItem>)re");
    int items = 0;
    for (auto it = std::sregex_iterator(xdmf.begin(), xdmf.end(), item); it != std::sregex_iterator(); ++it, ++items) {
      std::vector<hsize_t> expected;
      std::istringstream dims((*it)[1].str());
      for (hsize_t d; dims >> d;) expected.push_back(d);
      io::hdf5::Quiet quiet;
      io::hdf5::Handle file = io::hdf5::open_file_readonly(dir / "run" / (*it)[2].str());
      ASSERT_TRUE(file.valid()) << (*it)[2].str();
      std::vector<hsize_t> found;
      EXPECT_TRUE(io::hdf5::dataset_dims(file.get(), (*it)[3].str(), found)) << (*it)[3].str();
      EXPECT_EQ(found, expected) << (*it)[2].str() << ":" << (*it)[3].str();
    }
    EXPECT_EQ(items, series == std::string("fluid.xdmf") ? 2 * 3 : 2 * 8) << series;  // frames 0 and 1 (step 3)
  }
  // Frame 1 is step 3: its nodes are the checkpoint's positions, bitwise; its pressure the checkpoint's.
  const io::Checkpoint ck = io::Checkpoint::read(dir / "run" / "checkpoint.h5");
  io::hdf5::Handle file = io::hdf5::open_file_readonly(dir / "run" / "fields_000001.h5");
  std::vector<double> nodes, pressure;
  std::vector<hsize_t> dims;
  ASSERT_TRUE(io::hdf5::read_doubles(file.get(), "membranes/nodes", nodes, dims));
  EXPECT_EQ(nodes, positions(ck));
  ASSERT_TRUE(io::hdf5::read_doubles(file.get(), "fluid/pressure", pressure, dims));
  EXPECT_EQ(pressure, ck.array("fluid.p"));
  std::vector<std::int64_t> offsets;
  ASSERT_TRUE(io::hdf5::read_int64(file.get(), "membranes/node_offsets", offsets, dims));
  ASSERT_EQ(offsets.size(), 33u);
  EXPECT_EQ(offsets.back(), 32 * 642);
  std::vector<std::int32_t> conn;
  ASSERT_TRUE(io::hdf5::read_int32(file.get(), "membranes/connectivity", conn, dims));
  EXPECT_EQ(*std::max_element(conn.begin(), conn.end()), 32 * 642 - 1);
  EXPECT_EQ(*std::min_element(conn.begin(), conn.end()), 0);
}

TEST(RunMpi, UnstableRunStopsEveryProcessWithStatus3AndItsLastState) {
  ScratchDir dir("run_mpi");
  auto args = channel_args(dir / "run", 6);
  args.insert(args.end(), {"--set", "time.max_speed=3e-4"});  // the channel's flow reaches 3.6e-4 m/s in its centre
  const auto r = run_mpi(3, args, dir / "run");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  // The face by its global index and the value that exceeded the bound, as in one process.
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"(^immerse: run stopped: unstable at step 1, t = 2e-05: fluid )"
                                                  R"(velocity u_y at face \(\d+, \d+, \d+\) exceeds time\.max_speed )"
                                                  R"(\(runaway\) \(\|u_y\| = [0-9.e+-]+ m/s, bound 0\.0003\)\n)")))
      << r.err;
  // As in one process, the unstable state is saved beside the checkpoint for inspection; none was due yet.
  EXPECT_NE(r.err.find("\nimmerse: no checkpoint kept: none was written before step 1 (output.checkpoint_every = 3); "
                       "the state of step 1 is in " + (dir / "run" / "unstable_state.h5").string() +
                       "; start again with half the step: mpiexec -n 3 "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "run" / "checkpoint.h5"));
  EXPECT_EQ(io::Checkpoint::read(dir / "run" / "unstable_state.h5").get_int("step"), 1);
}

/// The words of the command at the end of the last line of an unstable run ("... with half the step: COMMAND").
std::vector<std::string> suggested_command(const std::string& err) {
  const std::string marker = " with half the step: ";
  const auto at = err.rfind(marker);
  if (at == std::string::npos) return {};
  const auto end = err.find('\n', at);
  return shell_words(err.substr(at + marker.size(), end == std::string::npos ? end : end - at - marker.size()));
}

// The small oscillating membrane (as kind "custom", which runs distributed) with the contour forces and forward Euler
// past their explicit limit on 2 processes, a checkpoint every 2 steps: it runs away at step 9, checkpoint.h5 keeps
// step 8, and the command of the last line, run as printed, continues with half the step to the end.
TEST(RunMpi, UnstableRunKeepsTheLastGoodCheckpointAndContinuesWithHalfTheStep) {
  ScratchDir dir("run_mpi");
  const fs::path out = dir / "run";
  const auto r = run_mpi(2,
                         run_args(scenario_file("oscillating_membrane_quick.toml"), out,
                                  {"scenario.kind=\"custom\"", "grid.nx=16", "grid.ny=16", "grid.nz=16",
                                   "membrane[0].mesh.level=1", "membrane[0].force=\"contour\"", "time.scheme=\"euler\"",
                                   "time.dt=0.35", "time.end=7.0", "time.max_speed=1.0", "output.fields_every=0",
                                   "output.checkpoint_every=2"}),
                         dir / "run");
  ASSERT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex(R"(^immerse: run stopped: unstable at step (\d+), t = )")))
      << r.err;
  const long step = std::stol(m[1]);
  ASSERT_GE(step, 3) << "the run must become unstable after its first checkpoint";
  const long kept = 2 * ((step - 1) / 2);
  EXPECT_EQ(io::Checkpoint::read(out / "checkpoint.h5").get_int("step"), kept);
  EXPECT_EQ(io::Checkpoint::read(out / "unstable_state.h5").get_int("step"), step);
  EXPECT_NE(r.err.find("\nimmerse: kept the last good checkpoint " + (out / "checkpoint.h5").string() + " (step " +
                       std::to_string(kept) + ", t = "),
            std::string::npos)
      << r.err;

  // mpiexec -n 2 PROGRAM run FILE --out DIR ... --restart DIR/checkpoint.h5 --set time.dt=0.175
  const auto words = suggested_command(r.err);
  ASSERT_GE(words.size(), 5u) << r.err;
  EXPECT_EQ(std::vector<std::string>(words.begin(), words.begin() + 4),
            (std::vector<std::string>{"mpiexec", "-n", "2", immerse_program().string()}));
  EXPECT_EQ(words.back(), "time.dt=0.175");
  const auto again = run_mpi(2, {words.begin() + 4, words.end()}, dir / "again");
  ASSERT_EQ(again.status, 0) << again.err;
  const io::Checkpoint last = io::Checkpoint::read(out / "checkpoint.h5");
  EXPECT_EQ(last.get_int("step"), kept + std::lround((7.0 - 0.35 * double(kept)) / 0.175));
  EXPECT_NEAR(last.get_double("fluid.time"), 7.0, 1e-9);
  EXPECT_FALSE(fs::exists(out / "unstable_state.h5"));
}

// Forward Euler at 2e-4 s folds an element of a cell of the quick channel: on 2 processes the message names it with
// its area ratio, the wall and the nearest other cell (searched on every process), as the one-process run does.
TEST(RunMpi, InvertedElementIsNamedAsInOneProcess) {
  ScratchDir dir("run_mpi");
  const auto args = [&](const std::string& name) {
    return run_args(scenario_file("rbc_channel_quick.toml"), dir / name,
                    {"time.scheme=\"euler\"", "time.dt=2e-4", "time.end=0.02", "output.fields_every=0",
                     "output.checkpoint_every=0"});
  };
  const auto two = run_mpi(2, args("two"), dir / "two");
  const auto one = run_immerse(args("one"), dir / "one");
  ASSERT_EQ(two.status, 3) << two.err;
  ASSERT_EQ(one.status, 3) << one.err;
  const std::string first = two.err.substr(0, two.err.find('\n'));
  EXPECT_EQ(first, one.err.substr(0, one.err.find('\n')));
  const std::regex line(R"(immerse: run stopped: step \d+, t = [0-9.e+-]+: membrane\[\d+\] element \d+: Jacobian <= 0 )"
                        R"(or not finite \(element inverted or degenerate\); area ratio [0-9.e+-]+ \(least of the )"
                        R"(membrane [0-9.e+-]+, element \d+\), [0-9.e+-]+ m from the wall [xz] = [0-9.e+-]+, )"
                        R"([0-9.e+-]+ m from membrane\[\d+\])");
  EXPECT_TRUE(std::regex_match(first, line)) << first;
}

TEST(RunMpi, StopSignalToOneProcessStopsAllAfterTheSameStepWithACheckpoint) {
  ScratchDir dir("run_mpi");
  auto args = channel_args(dir / "run", 500);
  const pid_t mpiexec = start_mpi(2, args, dir / "run");
  // Once a few rows are written (however long that takes), a scheduler's SIGTERM reaches one of the processes.
  for (;;) {
    const std::string rows = read_text(dir / "run" / "diagnostics.csv");
    if (std::count(rows.begin(), rows.end(), '\n') >= 4) break;
    int st = 0;
    ASSERT_EQ(waitpid(mpiexec, &st, WNOHANG), 0) << "the run ended before its fourth row:\n"
                                                 << read_text(dir / "run.stderr");
    usleep(100000);
  }
  const auto ranks = children(mpiexec);
  ASSERT_EQ(ranks.size(), 2u);
  kill(ranks.back(), SIGTERM);
  const auto r = wait_mpi(mpiexec, dir / "run");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: interrupted by signal 15 at step ", 0), 0u) << r.err;
  // Not before the last row seen (step 2): the signal may arrive before step 3 starts, and the run then stops there.
  const io::Checkpoint ck = io::Checkpoint::read(dir / "run" / "checkpoint.h5");
  EXPECT_GE(ck.get_int("step"), 2);
  EXPECT_LT(ck.get_int("step"), 500);
  EXPECT_NE(r.err.find("at step " + std::to_string(ck.get_int("step")) + ","), std::string::npos) << r.err;
}


// A SIGTERM reaching one of 2 processes while [packing] places the cells (59 red cells at H = 0.4 in the quick
// suspension take minutes): both stop at once with status 4, one line, and nothing written. The signal is sent once
// both processes catch it (MPI started, the run under way), however long their start takes.
TEST(RunMpi, StopSignalWhilePackingStopsEveryProcessAndWritesNothing) {
  ScratchDir dir("run_mpi");
  const fs::path out = dir / "run";
  const pid_t mpiexec =
      start_mpi(2, run_args(scenario_file("suspension_shear_quick.toml"), out, {"packing.volume_fraction=0.4"}), out);
  for (;;) {
    const auto ranks = children(mpiexec);
    if (ranks.size() == 2 && catches_sigterm(ranks[0]) && catches_sigterm(ranks[1])) {
      kill(ranks.back(), SIGTERM);
      break;
    }
    int st = 0;
    ASSERT_EQ(waitpid(mpiexec, &st, WNOHANG), 0) << "the run ended before the signal:\n" << read_text(dir / "run.stderr");
    usleep(20000);
  }
  const auto r = wait_mpi(mpiexec, out);
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_EQ(r.err, "immerse: interrupted by signal 15 while packing the cells, before the first step; nothing "
                   "written\n");
  EXPECT_FALSE(fs::exists(out));
}

// A step rejected and halved again and again on 2 processes (one Newton iteration allowed, a tolerance no iterate
// meets): a SIGTERM to one process stops both between two attempts, without waiting for the step to be accepted;
// the checkpoint holds the last accepted state (step 0).
TEST(RunMpi, StopSignalBetweenAttemptsOfAHalvedStepStopsEveryProcess) {
  ScratchDir dir("run_mpi");
  const fs::path out = dir / "run";
  const pid_t mpiexec = start_mpi(2,
                                  run_args(scenario_file("rbc_channel_quick.toml"), out,
                                           {"time.scheme=jfnk", "time.dt=2e-5", "solver.max_newton_its=1",
                                            "solver.newton_rtol=1e-300", "time.dt_min=1e-300"}),
                                  out);
  while (read_text(dir / "run.stdout").find("step 1, t = 0: step rejected with dt = ") == std::string::npos) {
    int st = 0;
    ASSERT_EQ(waitpid(mpiexec, &st, WNOHANG), 0) << "the run ended without a rejected step:\n"
                                                 << read_text(dir / "run.stdout") << read_text(dir / "run.stderr");
    usleep(20000);
  }
  const auto ranks = children(mpiexec);
  ASSERT_EQ(ranks.size(), 2u);
  kill(ranks.back(), SIGTERM);
  const auto r = wait_mpi(mpiexec, out);
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: interrupted by signal 15 at step 0, t = 0; checkpoint written to", 0), 0u) << r.err;
  EXPECT_EQ(io::Checkpoint::read(out / "checkpoint.h5").get_int("step"), 0);
}

// The summary of a 2-process run: the step profile (each part the largest over the processes) and the peak memory
// of the largest process and of all; FFTW's measured plans (fluid.fft_planning = "measure") give the positions of
// the estimated ones within round-off.
TEST(RunMpi, SummaryHasTheStepProfileAndMeasuredPlansGiveTheSameRun) {
  ScratchDir dir("run_mpi");
  auto estimate = channel_args(dir / "estimate", 3), measure = channel_args(dir / "measure", 3);
  measure.insert(measure.end(), {"--set", "fluid.fft_planning=measure"});
  const auto a = run_mpi(2, estimate, dir / "estimate"), b = run_mpi(2, measure, dir / "measure");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const std::regex profile(R"(ms per step \(% of the wall time\): membrane forces [0-9.]+ \(\d+ %\), contact [0-9.]+ )"
                           R"(\(\d+ %\), spreading [0-9.]+ \(\d+ %\), fluid [0-9.]+ \(\d+ %\), interpolation [0-9.]+ )"
                           R"(\(\d+ %\), the rest -?[0-9.]+ \(-?\d+ %\) \(each part the largest over the processes\)\n)");
  EXPECT_TRUE(std::regex_search(a.out, profile)) << a.out;
  EXPECT_TRUE(std::regex_search(a.out, std::regex(R"(\npeak memory [0-9.]+ [GM]B on the largest process, [0-9.]+ [GM]B in all\n)")))
      << a.out;
  const auto x = positions(io::Checkpoint::read(dir / "estimate" / "checkpoint.h5"));
  EXPECT_LT(relative_difference(positions(io::Checkpoint::read(dir / "measure" / "checkpoint.h5")), x), 1e-10);
}

// A grid whose slab does not fit in the memory a process may use is refused on every process before anything is
// allocated: one line naming the grid, the share of each process and the limit, status 2, nothing written.
TEST(RunMpi, GridBeyondTheMemoryOfAProcessIsRefused) {
  ScratchDir dir("run_mpi");
  auto sets = small_membrane_sets(1);
  sets.insert(sets.end(), {"grid.nx=2048", "grid.ny=2048", "grid.nz=1024"});  // 537 GB per process
  const auto r = run_mpi(2, run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "run", sets), dir / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: error: grid 2048 x 2048 x 1024 = 4.29e+09 cells over 2 processes: needs at least "
                        "537 GB per process, more than ",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "run"));
}

// Each process's thread governor: unbound processes without OMP_NUM_THREADS choose their thread count by
// measurement (adaptive where a process has 2 CPUs or more, fixed at 1 otherwise), the summary says so, and the
// run's checkpoint is bitwise that of one thread per process.
TEST(RunMpi, EachProcessChoosesItsThreadsWithoutChangingTheResults) {
  ScratchDir dir("run_mpi");
  auto args = [&](const std::string& name) {
    return run_args(scenario_file("rbc_channel_quick.toml"), dir / name,
                    {"time.scheme=jfnk", "time.dt=2e-5", "time.end=1e-4", "output.fields_every=0"});
  };
  const auto governed = run_mpi(2, args("governed"), dir / "governed", true);
  const auto one = run_mpi(2, args("one"), dir / "one");
  ASSERT_EQ(governed.status, 0) << governed.err;
  ASSERT_EQ(one.status, 0) << one.err;
  const std::string policy = AvailableCpus::of_this_process().count() >= 2
                                 ? R"(threads: 1 or \d+, chosen by measurement \([^)]*\): 1 thread for [0-9.]+ % of \d+ )"
                                   R"(evaluations, \d+ for [0-9.]+ %, \d+ switch(es)? )"
                                 : R"(threads: 1 \(fixed\) )";
  EXPECT_TRUE(std::regex_search(
      governed.out, std::regex(policy + R"(\(rank 0 of 2 MPI processes, each choosing its own\)\n)")))
      << governed.out;
  EXPECT_NE(one.out.find("threads: 1 (fixed by OMP_NUM_THREADS) (rank 0 of 2 MPI processes, each choosing its own)\n"),
            std::string::npos)
      << one.out;
  EXPECT_EQ(io::Checkpoint::read(dir / "governed" / "checkpoint.h5").checksum(),
            io::Checkpoint::read(dir / "one" / "checkpoint.h5").checksum());
}

}  // namespace
}  // namespace immerse::testing
