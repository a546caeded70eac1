// Restart is bitwise identical: N steps in one go, and N/2 steps then a restart from the checkpoint to N, end
// with equal checkpoints (every stored double bit for bit), equal diagnostics rows (all columns but the wall
// clock) and the same series of ParaView frames. For every membrane update scheme.
#include <gtest/gtest.h>

#include <sstream>

#include "PetscEnvironment.hpp"
#include "immerse/cli/RunCommand.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr int kSteps = 8;

int run(const fs::path& out, std::vector<std::string> sets, const fs::path& restart = {}) {
  std::ostringstream log, err;
  CommandLine o;
  o.file = scenario_file("oscillating_membrane_quick.toml");
  o.sets = std::move(sets);
  o.out = out;
  o.restart = restart;
  const int status = run_command(o, log, err);
  EXPECT_EQ(err.str(), "");
  return status;
}

std::vector<std::string> frame_files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("fields_", 0) == 0) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// kSteps steps in one go against kSteps / 2, a restart and kSteps / 2 more, with the membrane update `scheme` and
/// the further settings `extra`.
void expect_restart_bitwise(const std::string& scheme, const std::vector<std::string>& extra = {}) {
  ScratchDir dir("restart");
  auto sets = [&](int steps) {
    auto s = small_membrane_sets(steps);
    s.push_back("time.scheme=\"" + scheme + "\"");
    s.push_back("output.fields_every=3");
    s.insert(s.end(), extra.begin(), extra.end());
    return s;
  };
  ASSERT_EQ(run(dir / "whole", sets(kSteps)), 0);
  ASSERT_EQ(run(dir / "split", sets(kSteps / 2)), 0);
  const auto half = io::Checkpoint::read(dir / "split" / "checkpoint.h5");
  EXPECT_EQ(half.get_int("step"), kSteps / 2);
  ASSERT_EQ(run(dir / "split", sets(kSteps), dir / "split" / "checkpoint.h5"), 0);

  const auto whole = io::Checkpoint::read(dir / "whole" / "checkpoint.h5");
  const auto split = io::Checkpoint::read(dir / "split" / "checkpoint.h5");
  EXPECT_EQ(whole.get_int("step"), kSteps);
  EXPECT_TRUE(whole == split) << "checksums " << whole.checksum() << " vs " << split.checksum();

  const auto rows = without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv"));
  EXPECT_EQ(rows.size(), std::size_t(kSteps + 2));  // header, step 0, steps 1..kSteps
  EXPECT_EQ(rows, without_wall_clock(read_csv(dir / "split" / "diagnostics.csv")));

  // Frames at steps 0, 3, 6 and the last state (8), in both.
  EXPECT_EQ(frame_files(dir / "whole").size(), 4u);
  EXPECT_EQ(frame_files(dir / "whole"), frame_files(dir / "split"));
  EXPECT_EQ(read_text(dir / "whole" / "membranes.xdmf"), read_text(dir / "split" / "membranes.xdmf"));
  EXPECT_EQ(read_text(dir / "whole" / "fluid.xdmf"), read_text(dir / "split" / "fluid.xdmf"));
}

class RestartTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RestartTest, HalfRunPlusRestartEqualsOneRunBitwise) { expect_restart_bitwise(GetParam()); }

// The volume correction after each step is deterministic and moves the committed positions, which the checkpoint
// holds; the constraint forces are part of f(X).
TEST(RestartVolume, HalfRunPlusRestartEqualsOneRunBitwiseWithVolumeConstraintAndCorrection) {
  for (const char* scheme : {"jfnk", "rk2"})
    expect_restart_bitwise(scheme, {"membrane[0].volume_correction=\"normal_shift\"", "membrane[0].volume_modulus=5",
                                    "membrane[0].area_modulus=0.1"});
}

// A flow rate held along x (fluid.flow_rate): the force each step adds is in the checkpoint, and the energy budget
// continues with it.
TEST(RestartFlowRate, HalfRunPlusRestartEqualsOneRunBitwiseAtAFlowRate) {
  expect_restart_bitwise("jfnk", {"boundary.x=\"periodic\"", "fluid.flow_rate=[0.002,0,0]"});
}

INSTANTIATE_TEST_SUITE_P(Run, RestartTest, ::testing::Values("jfnk", "lbfgs", "bfgs", "euler", "rk2", "anderson"),
                         [](const auto& p) { return p.param; });

}  // namespace

// An rbc_stretch force sweep stopped by time.end in the middle of a force (exit 0, with a message) and continued
// with --restart ends like the uninterrupted sweep: the same checkpoint bit for bit, the same stretch.csv and
// diagnostics rows. dt = 2^-11 s, so that the stopping time is a whole number of steps exactly.
TEST(RestartSweep, ForceSweepContinuesBitwiseFromAMidSweepCheckpoint) {
  ScratchDir dir("restart_sweep");
  auto sets = [](const std::string& end) {
    return std::vector<std::string>{"grid.nx=16", "grid.ny=16", "grid.nz=16", "membrane[0].mesh.level=1",
                                    "scenario.forces_pN=[0, 60]", "scenario.steady_tol=0.02",
                                    "scenario.max_relaxation_times=2", "time.dt=4.8828125e-4", "time.end=" + end,
                                    "output.fields_every=0", "output.checkpoint_every=0"};
  };
  auto run_sweep = [&](const fs::path& out, const std::string& end, const fs::path& restart = {}) {
    std::ostringstream log, err;
    CommandLine o;
    o.file = scenario_file("rbc_stretch_quick.toml");
    o.sets = sets(end);
    o.out = out;
    o.restart = restart;
    EXPECT_EQ(run_command(o, log, err), 0) << err.str();
    EXPECT_EQ(err.str(), "");
    return log.str();
  };
  run_sweep(dir / "whole", "1.0");
  const std::string first = run_sweep(dir / "split", "0.00390625");  // 8 steps: during the second force
  EXPECT_NE(first.find("rbc_stretch: time.end reached during force 2 of 2 (60 pN)"), std::string::npos) << first;
  EXPECT_EQ(read_csv(dir / "split" / "stretch.csv").size(), 2u);  // header and the 0 pN row
  run_sweep(dir / "split", "1.0", dir / "split" / "checkpoint.h5");

  const auto whole = io::Checkpoint::read(dir / "whole" / "checkpoint.h5");
  const auto split = io::Checkpoint::read(dir / "split" / "checkpoint.h5");
  EXPECT_GT(whole.get_int("step"), 8);
  EXPECT_EQ(whole.get_int("sweep.current"), 2);  // done
  EXPECT_TRUE(whole == split) << "checksums " << whole.checksum() << " vs " << split.checksum();
  EXPECT_EQ(read_text(dir / "whole" / "stretch.csv"), read_text(dir / "split" / "stretch.csv"));
  EXPECT_EQ(read_csv(dir / "whole" / "stretch.csv").size(), 3u);
  EXPECT_EQ(without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv")),
            without_wall_clock(read_csv(dir / "split" / "diagnostics.csv")));
}

// A restart into another (new) folder branches the run: that folder holds a new series of rows, frames and
// checkpoints beginning at the checkpoint's step, with the same states as the uninterrupted run; the folder of
// the checkpoint is left as it was. The end time and the output schedule may differ from the first run's.
TEST(RestartBranch, ANewFolderStartsANewSeriesAtTheCheckpointStep) {
  ScratchDir dir("restart");
  auto sets = [](int steps, int fields_every) {
    auto s = small_membrane_sets(steps);
    s.push_back("output.fields_every=" + std::to_string(fields_every));
    return s;
  };
  ASSERT_EQ(run(dir / "whole", sets(kSteps, 1)), 0);
  ASSERT_EQ(run(dir / "first", sets(kSteps / 2, 2)), 0);
  const std::string first_rows = read_text(dir / "first" / "diagnostics.csv");
  const auto first_frames = frame_files(dir / "first");
  ASSERT_EQ(run(dir / "branch", sets(kSteps, 1), dir / "first" / "checkpoint.h5"), 0);

  EXPECT_EQ(read_text(dir / "first" / "diagnostics.csv"), first_rows);
  EXPECT_EQ(frame_files(dir / "first"), first_frames);
  const auto whole = io::Checkpoint::read(dir / "whole" / "checkpoint.h5");
  const auto branch = io::Checkpoint::read(dir / "branch" / "checkpoint.h5");
  EXPECT_TRUE(whole == branch) << "checksums " << whole.checksum() << " vs " << branch.checksum();

  // Rows of steps kSteps/2 .. kSteps: the branch point, then the same rows as the whole run (apart from the
  // branch point's solver columns, which describe no step of this run).
  const auto rows = without_wall_clock(read_csv(dir / "branch" / "diagnostics.csv"));
  const auto all = without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv"));
  ASSERT_EQ(rows.size(), std::size_t(kSteps / 2 + 2));
  EXPECT_EQ(rows[0], all[0]);
  EXPECT_EQ(std::stol(rows[1][0]), kSteps / 2);
  EXPECT_EQ(rows[1][1], all[kSteps / 2 + 1][1]);  // time of the branch point
  for (std::size_t r = 2; r < rows.size(); ++r) EXPECT_EQ(rows[r], all[kSteps / 2 + r]) << "row " << r;
  // One frame per step from the branch point: frames 0 .. kSteps/2, the first at the checkpoint's time.
  EXPECT_EQ(frame_files(dir / "branch").size(), std::size_t(kSteps / 2 + 1));
  const std::string series = read_text(dir / "branch" / "membranes.xdmf");
  EXPECT_NE(series.find("fields_000000.h5"), std::string::npos);
  EXPECT_EQ(series.find("fields_00000" + std::to_string(kSteps / 2 + 1) + ".h5"), std::string::npos);
}
