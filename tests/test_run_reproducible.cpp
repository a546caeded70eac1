// A run is reproducible bit for bit in separate processes: with one and with two threads, and when continued from
// a checkpoint by a new process (with either pressure of (9)). The grid (44^3 cells) is above
// MacGeom::kMinCellsForThreads, so the fluid solvers' loops and FFTW's transforms run threaded with two threads.
// This holds with fluid.fft_planning = "estimate" (the default), whose FFTW plans do not depend on timings; with
// "measure" the plans, and so the round-off, may change from one process to the next (docs/performance.md,
// "Reproducibility").
#include <gtest/gtest.h>

#include "immerse/io/Checkpoint.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr int kSteps = 4;

std::vector<std::string> threaded_sets(int steps) {
  auto s = small_membrane_sets(steps);
  s.insert(s.end(), {"grid.nx=44", "grid.ny=44", "grid.nz=44", "membrane[0].mesh.level=2"});
  return s;
}

int run(const fs::path& out, int steps, int threads, const fs::path& restart = {}, const std::string& scheme = "jfnk",
        const std::string& pressure = "lagged") {
  auto sets = threaded_sets(steps);
  sets.push_back("time.scheme=" + scheme);
  sets.push_back("fluid.pressure=" + pressure);
  const auto args = run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets, restart);
  const auto r = run_immerse(args, out.string() + "_log", {"OMP_NUM_THREADS=" + std::to_string(threads)});
  EXPECT_EQ(r.err, "");
  return r.status;
}

// For each implicit solver of the 3D runs: JFNK (the paper's) and Anderson acceleration.
class ThreadCount : public ::testing::TestWithParam<std::string> {};

TEST_P(ThreadCount, RunsWithOneAndTwoThreadsInSeparateProcessesAreBitwiseIdentical) {
  ScratchDir dir("reproducible");
  ASSERT_EQ(run(dir / "one", kSteps, 1, {}, GetParam()), 0);
  ASSERT_EQ(run(dir / "two", kSteps, 2, {}, GetParam()), 0);
  const auto one = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  const auto two = io::Checkpoint::read(dir / "two" / "checkpoint.h5");
  EXPECT_EQ(one.get_int("step"), kSteps);
  EXPECT_TRUE(one == two) << "checksums " << one.checksum() << " vs " << two.checksum();
  const auto rows = without_wall_clock(read_csv(dir / "one" / "diagnostics.csv"));
  EXPECT_EQ(rows.size(), std::size_t(kSteps + 2));
  EXPECT_EQ(rows, without_wall_clock(read_csv(dir / "two" / "diagnostics.csv")));
}

INSTANTIATE_TEST_SUITE_P(Reproducibility, ThreadCount, ::testing::Values("jfnk", "anderson"),
                         [](const auto& p) { return p.param; });

// For each pressure of (9): the extrapolated one needs the checkpoint's p^{n-3/2} at the restart (after two steps).
class Restart : public ::testing::TestWithParam<std::string> {};

TEST_P(Restart, InANewProcessContinuesBitwise) {
  ScratchDir dir("reproducible");
  const std::string pressure = GetParam();
  ASSERT_EQ(run(dir / "whole", kSteps, 2, {}, "jfnk", pressure), 0);
  ASSERT_EQ(run(dir / "split", kSteps / 2, 2, {}, "jfnk", pressure), 0);
  ASSERT_EQ(run(dir / "split", kSteps, 2, dir / "split" / "checkpoint.h5", "jfnk", pressure), 0);
  const auto whole = io::Checkpoint::read(dir / "whole" / "checkpoint.h5");
  const auto split = io::Checkpoint::read(dir / "split" / "checkpoint.h5");
  EXPECT_EQ(split.get_int("step"), kSteps);
  EXPECT_TRUE(whole == split) << "checksums " << whole.checksum() << " vs " << split.checksum();
  EXPECT_EQ(without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv")),
            without_wall_clock(read_csv(dir / "split" / "diagnostics.csv")));
}

INSTANTIATE_TEST_SUITE_P(Reproducibility, Restart, ::testing::Values("lagged", "extrapolated"),
                         [](const auto& p) { return p.param; });

}  // namespace
