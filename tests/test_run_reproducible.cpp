// A run is reproducible bit for bit in separate processes: with one and with two threads, and when continued from
// a checkpoint by a new process (with either pressure of (9)). The grid (44^3 cells) is above
// MacStencilGrid::kMinCellsForThreads, so the fluid solvers' loops and FFTW's transforms run threaded with two threads.
// This holds with fluid.fft_planning = "estimate" (the default), whose FFTW plans do not depend on timings; with
// "measure" the plans, and so the round-off, may change from one process to the next (docs/performance.md,
// "Reproducibility").
#include <gtest/gtest.h>

#include "immerse/core/ThreadGovernor.hpp"
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

std::string& last_stdout() {
  static std::string out;
  return out;
}

int run(const fs::path& out, int steps, int threads, const fs::path& restart = {}, const std::string& scheme = "jfnk",
        const std::string& pressure = "lagged") {
  auto sets = threaded_sets(steps);
  sets.push_back("time.scheme=" + scheme);
  sets.push_back("fluid.pressure=" + pressure);
  const auto args = run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets, restart);
  // threads = 0: OMP_NUM_THREADS unset (the count is then chosen by measurement).
  const auto r = run_immerse(args, out.string() + "_log",
                             {threads > 0 ? "OMP_NUM_THREADS=" + std::to_string(threads) : "OMP_NUM_THREADS"});
  EXPECT_EQ(r.err, "");
  last_stdout() = r.out;
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

// Without OMP_NUM_THREADS the thread count is chosen by measurement: the first evaluations run on both threads, the
// next on one, then on the cheaper, with probes of the other; the run is bitwise the one-thread run.
TEST(Reproducibility, ThreadCountChosenByMeasurementGivesTheOneThreadRunBitwise) {
  ScratchDir dir("reproducible");
  ASSERT_EQ(run(dir / "one", kSteps, 1), 0);
  ASSERT_EQ(run(dir / "chosen", kSteps, 0), 0);
  const std::string out = last_stdout();
  if (AvailableCpus::of_this_process().count() > 1) {
    const auto at = out.find("chosen by measurement");
    ASSERT_NE(at, std::string::npos) << out;
    // "1 thread for X % of N evaluations, 2 for Y %": both counts were used.
    const auto one = out.find("1 thread for ", at), two = out.find(" for ", out.find("evaluations, ", at));
    ASSERT_NE(one, std::string::npos) << out;
    ASSERT_NE(two, std::string::npos) << out;
    EXPECT_GT(std::stod(out.substr(one + 13)), 0.0) << out;
    EXPECT_GT(std::stod(out.substr(two + 5)), 0.0) << out;
  }
  const auto one = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  const auto chosen = io::Checkpoint::read(dir / "chosen" / "checkpoint.h5");
  EXPECT_TRUE(one == chosen) << "checksums " << one.checksum() << " vs " << chosen.checksum();
  EXPECT_EQ(without_wall_clock(read_csv(dir / "one" / "diagnostics.csv")),
            without_wall_clock(read_csv(dir / "chosen" / "diagnostics.csv")));
}

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

// A viscosity contrast (membrane[0].viscosity_ratio = 5): one thread, and two threads with a restart in the middle
// (which needs the checkpoint's u^{n-1}), bitwise the same; for an implicit solver of each kind and an explicit scheme.
class ViscosityContrast : public ::testing::TestWithParam<std::string> {};

TEST_P(ViscosityContrast, WithOneAndTwoThreadsAndAfterARestartIsBitwiseIdentical) {
  ScratchDir dir("reproducible");
  const auto go = [&](const fs::path& out, int steps, int threads, const fs::path& restart = {}) {
    auto sets = threaded_sets(steps);
    sets.insert(sets.end(), {"time.scheme=" + GetParam(), "membrane[0].viscosity_ratio=5"});
    const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets, restart),
                               out.string() + "_log", {"OMP_NUM_THREADS=" + std::to_string(threads)});
    EXPECT_EQ(r.err, "");
    return r.status;
  };
  // One thread for the whole run against two threads for a run split by a restart: both properties in one comparison.
  ASSERT_EQ(go(dir / "one", kSteps, 1), 0);
  ASSERT_EQ(go(dir / "split", kSteps / 2, 2), 0);
  ASSERT_EQ(go(dir / "split", kSteps, 2, dir / "split" / "checkpoint.h5"), 0);
  const auto one = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  const auto split = io::Checkpoint::read(dir / "split" / "checkpoint.h5");
  EXPECT_TRUE(one.has("fluid.u_prev0"));
  EXPECT_TRUE(one == split) << "checksums " << one.checksum() << " vs " << split.checksum();
  EXPECT_EQ(without_wall_clock(read_csv(dir / "one" / "diagnostics.csv")),
            without_wall_clock(read_csv(dir / "split" / "diagnostics.csv")));
}

INSTANTIATE_TEST_SUITE_P(Reproducibility, ViscosityContrast, ::testing::Values("jfnk", "anderson", "euler"),
                         [](const auto& p) { return p.param; });

// Two oscillating membranes (1026 nodes each: the contact loop runs threaded with two threads) 0.05 apart and 0.075
// from the walls x = 0, 1, with contact.range = 0.08: contact forces between them and from the walls at every step.
int run_in_contact(const ScratchDir& dir, const std::string& name, int steps, int threads, bool restart = false) {
  const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
  std::string toml = base.substr(0, base.find("[[membrane]]"));
  for (const char* x : {"0.275", "0.725"})
    toml += std::string("[[membrane]]\nshape = \"ellipsoid\"\nsemi_axes = [0.2, 0.19, 0.18]\nreference = \"sphere\"\n") +
            "reference_radius = 0.18\ncenter = [" + x + ", 0.5, 0.5]\nEs = 0.1\nmesh.family = \"octahedral\"\n" +
            "mesh.level = 3\n";
  std::ofstream(dir / "contact.toml") << toml;
  auto sets = small_run_sets(steps, 0.02);
  sets.insert(sets.end(), {"grid.nx=24", "grid.ny=24", "grid.nz=24", "contact.range=0.08"});
  const fs::path out = dir / name;
  const auto r = run_immerse(run_args(dir / "contact.toml", out, sets, restart ? out / "checkpoint.h5" : fs::path{}),
                             out.string() + "_log", {"OMP_NUM_THREADS=" + std::to_string(threads)});
  EXPECT_EQ(r.err, "");
  return r.status;
}

TEST(Reproducibility, ContactForcesWithOneAndTwoThreadsAndAfterARestartAreBitwiseIdentical) {
  ScratchDir dir("reproducible");
  ASSERT_EQ(run_in_contact(dir, "one", kSteps, 1), 0);
  ASSERT_EQ(run_in_contact(dir, "two", kSteps, 2), 0);
  ASSERT_EQ(run_in_contact(dir, "split", kSteps / 2, 2), 0);
  ASSERT_EQ(run_in_contact(dir, "split", kSteps, 2, true), 0);
  const auto one = io::Checkpoint::read(dir / "one" / "checkpoint.h5");
  for (const char* other : {"two", "split"}) {
    const auto c = io::Checkpoint::read(dir / other / "checkpoint.h5");
    EXPECT_EQ(c.get_int("step"), kSteps) << other;
    EXPECT_TRUE(one == c) << other << ": checksums " << one.checksum() << " vs " << c.checksum();
    EXPECT_EQ(without_wall_clock(read_csv(dir / "one" / "diagnostics.csv")),
              without_wall_clock(read_csv(dir / other / "diagnostics.csv")))
        << other;
  }
}

}  // namespace
