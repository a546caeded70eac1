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
