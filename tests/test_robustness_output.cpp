// Output that cannot be written is reported, never ignored. Tests run as root, for whom permission bits do not
// block writes (chmod 555 on a folder changes nothing), so the failures are made in ways that hold for root too:
//   - an output folder under a regular file (ENOTDIR) or inside /proc (the kernel refuses new entries there):
//     `immerse run` exits with status 2 and one line "cannot write <folder>: <reason>" before writing anything;
//   - a full disk, imitated by a file-size limit (RLIMIT_FSIZE, with SIGXFSZ ignored so that write() fails with
//     EFBIG instead of killing the process): the run stops with status 5 and one line naming the step, the time
//     and the file, keeps the files written before it complete and leaves no temporary behind;
//   - a damaged diagnostics.csv met by a restart is refused (status 2) before anything is rewritten.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <cstdlib>
#include <map>

#include "immerse/membrane/MeshGenerator.hpp"
#include "test_run_support.hpp"

using namespace immerse::testing;

namespace {

void expect_one_error_line(const RunResult& r, int status, const std::string& start, const std::string& part) {
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_EQ(r.err.rfind(start, 0), 0u) << r.err;
  EXPECT_NE(r.err.find(part), std::string::npos) << "expected: " << part << "\ngot: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

/// run_immerse with every file the child writes limited to `bytes` (the limit, the ignored SIGXFSZ and the
/// environment are inherited through posix_spawn; this process gets its own back at once). PMIX_MCA_gds=hash
/// keeps OpenMPI's PMIx (started by PETSc) from putting its data store in shared-memory files, which the limit
/// would hit before immerse writes anything.
RunResult run_with_file_size_limit(const std::vector<std::string>& args, const fs::path& log, rlim_t bytes) {
  setenv("PMIX_MCA_gds", "hash", 1);
  rlimit saved{};
  getrlimit(RLIMIT_FSIZE, &saved);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = saved;
  limited.rlim_cur = bytes;
  setrlimit(RLIMIT_FSIZE, &limited);
  ImmerseProcess p(args, log);
  setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);
  unsetenv("PMIX_MCA_gds");
  const int status = p.wait();
  return {status, p.out(), p.err()};
}

std::vector<fs::path> temporaries(const fs::path& dir) {
  std::vector<fs::path> t;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) t.push_back(e.path());
  return t;
}

}  // namespace

TEST(RobustnessOutput, FolderUnderARegularFileIsRefusedBeforeAnything) {
  ScratchDir scratch("output");
  std::ofstream(scratch / "file") << "a regular file\n";
  const fs::path out = scratch / "file" / "out";
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(1)),
                             scratch / "run");
  expect_one_error_line(r, 2, "immerse: error: ", "cannot write " + out.string() + ": Not a directory");
  EXPECT_EQ(read_text(scratch / "file"), "a regular file\n");
}

TEST(RobustnessOutput, FolderInProcIsRefusedBeforeAnything) {
  const fs::path out = "/proc/immerse_test_out_" + std::to_string(getpid());
  ScratchDir scratch("output");
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(1)),
                             scratch / "run");
  expect_one_error_line(r, 2, "immerse: error: ", "cannot write " + out.string() + ": No such file or directory");
  EXPECT_FALSE(fs::exists(out));
}

// config.resolved.toml (about 13 kB) and diagnostics.csv fit under the limit; a frame (16^3 fluid fields,
// about 200 kB) and a checkpoint (about 140 kB) do not.
constexpr rlim_t kLimit = 64 * 1024;

TEST(RobustnessOutput, FullDiskWhileWritingAFrameStopsTheRunWithStatus5) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  auto sets = small_membrane_sets(3);
  sets.push_back("output.fields_every=1");
  const auto r = run_with_file_size_limit(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets),
                                          scratch / "run", kLimit);
  expect_one_error_line(r, 5, "immerse: run stopped at step 0, t = 0: ",
                        "cannot write " + (out / "fields_000000.h5").string() + ": File too large");
  EXPECT_NE(r.err.find("(no checkpoint written)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "fields_000000.h5"));
  EXPECT_TRUE(temporaries(out).empty());
  const auto rows = read_csv(out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 2u);  // the header and the step-0 row, written before the frame
  EXPECT_EQ(rows[1][0], "0");
}

TEST(RobustnessOutput, FullDiskWhileWritingACheckpointStopsTheRunWithStatus5) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  auto sets = small_membrane_sets(3);
  sets.push_back("output.checkpoint_every=2");
  const auto r = run_with_file_size_limit(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets),
                                          scratch / "run", kLimit);
  expect_one_error_line(r, 5, "immerse: run stopped at step 2, t = 0.25: ",
                        "cannot write " + (out / "checkpoint.h5").string() + ": File too large (no checkpoint written)");
  EXPECT_FALSE(fs::exists(out / "checkpoint.h5"));
  EXPECT_TRUE(temporaries(out).empty());
  const auto rows = read_csv(out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 4u);  // the header and steps 0, 1, 2: every row of every completed step is kept
  EXPECT_EQ(rows[3][0], "2");
}

TEST(RobustnessOutput, RestartRefusesADamagedDiagnosticsFileBeforeRewritingAnything) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  const auto first = run_immerse(run_args(file, out, small_membrane_sets(1)), scratch / "first");
  ASSERT_EQ(first.status, 0) << first.err;
  std::ofstream(out / "diagnostics.csv", std::ios::app) << "garbage\n";
  const std::string config_before = read_text(out / "config.resolved.toml");
  const std::string diagnostics_before = read_text(out / "diagnostics.csv");
  const auto again = run_immerse(run_args(file, out, small_membrane_sets(2), out / "checkpoint.h5"), scratch / "again");
  expect_one_error_line(again, 2, "immerse: error: ",
                        "cannot continue " + (out / "diagnostics.csv").string() +
                            ": line 4 is not a row of numbers (damaged file)");
  EXPECT_EQ(read_text(out / "diagnostics.csv"), diagnostics_before);
  EXPECT_EQ(read_text(out / "config.resolved.toml"), config_before);
}

namespace {

/// Every file of a folder with its content.
std::map<std::string, std::string> folder_contents(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) files[e.path().filename().string()] = read_text(e.path());
  return files;
}

std::vector<std::string> with_frames(std::vector<std::string> sets) {
  sets.push_back("output.fields_every=1");
  return sets;
}

}  // namespace

// A folder that holds a run is refused to a second run, changed in nothing; --overwrite replaces the run's own
// files and keeps the user's.
TEST(RobustnessOutput, FolderHoldingARunIsRefusedUnlessOverwriteIsGiven) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  ASSERT_EQ(run_immerse(run_args(file, out, with_frames(small_membrane_sets(2))), scratch / "first").status, 0);
  std::ofstream(out / "notes.txt") << "the user's own file\n";
  const auto before = folder_contents(out);
  ASSERT_TRUE(before.contains("fields_000002.h5"));

  const auto again = run_immerse(run_args(file, out, small_membrane_sets(1)), scratch / "again");
  expect_one_error_line(again, 2, "immerse: error: ",
                        "--out " + out.string() +
                            " holds another run (checkpoint.h5, config.resolved.toml, diagnostics.columns.csv, ...): choose "
                            "another folder, continue it with --restart " + (out / "checkpoint.h5").string() +
                            ", or replace it with --overwrite");
  EXPECT_EQ(again.out, "");
  EXPECT_TRUE(folder_contents(out) == before) << "the refused run changed the folder";

  auto args = run_args(file, out, small_membrane_sets(1));
  args.push_back("--overwrite");
  const auto replaced = run_immerse(args, scratch / "replaced");
  ASSERT_EQ(replaced.status, 0) << replaced.err;
  const auto after = folder_contents(out);
  EXPECT_EQ(after.at("notes.txt"), "the user's own file\n");
  for (const auto& [name, text] : after)
    EXPECT_TRUE(name.rfind("fields_", 0) != 0 && name.find("xdmf") == std::string::npos) << name << " was kept";
  EXPECT_EQ(read_csv(out / "diagnostics.csv").size(), 3u);  // header, steps 0 and 1 of the new run
}

// A restart from one run's checkpoint into the folder of another run is refused before anything there changes;
// continuing a run in its own folder is not combined with --overwrite.
TEST(RobustnessOutput, RestartIntoTheFolderOfAnotherRunIsRefused) {
  ScratchDir scratch("output");
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  ASSERT_EQ(run_immerse(run_args(file, scratch / "a", small_membrane_sets(1)), scratch / "a_run").status, 0);
  auto other = small_membrane_sets(2);
  other.push_back("fluid.mu=0.02");
  ASSERT_EQ(run_immerse(run_args(file, scratch / "b", other), scratch / "b_run").status, 0);
  const auto before = folder_contents(scratch / "b");

  const auto into_b = run_immerse(run_args(file, scratch / "b", small_membrane_sets(3), scratch / "a" / "checkpoint.h5"),
                                  scratch / "into_b");
  expect_one_error_line(into_b, 2, "immerse: error: ",
                        "--out " + (scratch / "b").string() +
                            " holds another run (checkpoint.h5, config.resolved.toml, diagnostics.columns.csv, ...): choose another "
                            "folder, restart from that run's own checkpoint, or replace it with --overwrite");
  EXPECT_TRUE(folder_contents(scratch / "b") == before) << "the refused restart changed the other run's folder";

  auto args = run_args(file, scratch / "a", small_membrane_sets(3), scratch / "a" / "checkpoint.h5");
  args.push_back("--overwrite");
  const auto both = run_immerse(args, scratch / "both");
  expect_one_error_line(both, 2, "immerse: error: ",
                        "--overwrite: would remove the run that --restart " + (scratch / "a" / "checkpoint.h5").string() +
                            " continues (leave out --overwrite to continue it in " + (scratch / "a").string() + ")");
}

// A temporary left by a writer that was killed (NAME.tmp.PID of a run file) is removed by the next run into the
// folder; a user's file of a similar name is not.
TEST(RobustnessOutput, TemporaryOfAKilledWriterIsRemovedAtTheNextRun) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  ASSERT_EQ(run_immerse(run_args(file, out, small_membrane_sets(1)), scratch / "first").status, 0);
  std::ofstream(out / "checkpoint.h5.tmp.4242") << "half a checkpoint";
  std::ofstream(out / "notes.txt.tmp.4242") << "the user's own file\n";
  const auto again = run_immerse(run_args(file, out, small_membrane_sets(2), out / "checkpoint.h5"), scratch / "again");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_FALSE(fs::exists(out / "checkpoint.h5.tmp.4242"));
  EXPECT_TRUE(fs::exists(out / "notes.txt.tmp.4242"));
}

// The first files of a new folder cannot be written: the copy of the membrane's mesh file, made longer than the
// file-size limit by a 70 kB comment section (a lower limit would hit OpenMPI's own files first), after
// config.resolved.toml. The folder is not left behind, and the status says nothing was written.
TEST(RobustnessOutput, NewFolderIsRemovedWhenItsFirstFileCannotBeWritten) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  write_gmsh(scratch / "cell.msh", immerse::octahedral_sphere(1), {0.2, 0.2, 0.2});
  std::ofstream(scratch / "cell.msh", std::ios::app) << "$Comments\n" << std::string(70000, 'x') << "\n$EndComments\n";
  std::ofstream(scratch / "cell.toml") << file_membrane_toml("cell.msh");
  const auto r = run_with_file_size_limit(run_args(scratch / "cell.toml", out, small_run_sets(1)), scratch / "run", kLimit);
  expect_one_error_line(r, 2, "immerse: error: ",
                        "cannot write " + (out / "mesh_membrane0.msh").string() + ": File too large");
  EXPECT_FALSE(fs::exists(out));
}

// The final checkpoint (written at the end of every run) cannot be written: status 5, not 2, with the one line
// of a failed write; the diagnostics of every step are kept.
TEST(RobustnessOutput, FullDiskWhileWritingTheFinalCheckpointStopsWithStatus5) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  const auto r = run_with_file_size_limit(
      run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(3)), scratch / "run", kLimit);
  expect_one_error_line(r, 5, "immerse: run stopped at step 3, t = 0.375: ",
                        "cannot write " + (out / "checkpoint.h5").string() + ": File too large (no checkpoint written)");
  EXPECT_FALSE(fs::exists(out / "checkpoint.h5"));
  EXPECT_TRUE(temporaries(out).empty());
  EXPECT_EQ(read_csv(out / "diagnostics.csv").size(), 5u);  // header, steps 0..3
}

// An instability whose unstable state cannot be written: the instability is reported, then the failed write, and
// the status is that of the failed write (5).
TEST(RobustnessOutput, FullDiskAfterAnInstabilityStopsWithStatus5) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  auto sets = small_membrane_sets(100);
  // The contour forces of eq. (42): forward Euler past their explicit limit runs away (with -dE/dX on this mesh it
  // is stable at this step, and folds an element at a larger one).
  sets.insert(sets.end(), {"time.scheme=\"euler\"", "time.dt=0.35", "time.end=35.0", "time.max_speed=1.0",
                           "membrane[0].force=\"contour\""});
  const auto r = run_with_file_size_limit(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets),
                                          scratch / "run", kLimit);
  EXPECT_EQ(r.status, 5) << r.err;
  const auto second = r.err.find('\n') + 1;
  EXPECT_EQ(r.err.rfind("immerse: run stopped: unstable at step ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("immerse: run stopped at step ", second), second) << r.err;
  EXPECT_NE(r.err.find("cannot write " + (out / "unstable_state.h5").string() +
                           ": File too large (no checkpoint written)\n",
                       second),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
}

namespace {

/// cell.toml with a mesh file whose copy in the run folder exceeds kLimit, in `scratch`.
void write_large_mesh_config(const ScratchDir& scratch) {
  write_gmsh(scratch / "cell.msh", immerse::octahedral_sphere(1), {0.2, 0.2, 0.2});
  std::ofstream(scratch / "cell.msh", std::ios::app) << "$Comments\n" << std::string(70000, 'x') << "\n$EndComments\n";
  std::ofstream(scratch / "cell.toml") << file_membrane_toml("cell.msh");
}

}  // namespace

// An existing folder (a file of the user's in it) whose first run files cannot all be written: the ones written are
// removed again, exit 2, the folder as it was.
TEST(RobustnessOutput, ExistingFolderIsLeftAsItWasWhenItsFirstFilesCannotBeWritten) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "the user's notes\n";
  write_large_mesh_config(scratch);
  const auto before = folder_contents(out);
  const auto r = run_with_file_size_limit(run_args(scratch / "cell.toml", out, small_run_sets(1)), scratch / "run", kLimit);
  expect_one_error_line(r, 2, "immerse: error: ",
                        "cannot write " + (out / "mesh_membrane0.msh").string() + ": File too large");
  EXPECT_EQ(folder_contents(out), before);
}

// --overwrite of a folder holding a run, whose new first files cannot all be written: the old run is put back.
TEST(RobustnessOutput, OverwrittenRunIsPutBackWhenTheNewFirstFilesCannotBeWritten) {
  ScratchDir scratch("output");
  const fs::path out = scratch / "out";
  auto sets = small_membrane_sets(1);
  sets.push_back("output.fields_every=1");
  ASSERT_EQ(run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets), scratch / "first").status,
            0);
  std::ofstream(out / "notes.txt") << "the user's notes\n";
  write_large_mesh_config(scratch);
  const auto before = folder_contents(out);
  auto args = run_args(scratch / "cell.toml", out, small_run_sets(1));
  args.push_back("--overwrite");
  const auto r = run_with_file_size_limit(args, scratch / "run", kLimit);
  expect_one_error_line(r, 2, "immerse: error: ",
                        "cannot write " + (out / "mesh_membrane0.msh").string() + ": File too large");
  EXPECT_EQ(folder_contents(out), before);
}
