// SIGTERM and SIGINT to a running `immerse run`: the program finishes the step it is on, writes a checkpoint of it,
// exits with status 4; restarting from that checkpoint to the end gives bitwise the checkpoint and the diagnostics
// of an uninterrupted run.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <thread>

#include "immerse/io/Checkpoint.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr int kLongRun = 100000;  // steps: far more than the test waits for
constexpr int kRowsBeforeSignal = 3, kStepsAfterSignal = 3;

std::size_t rows_written(const fs::path& csv) {
  const std::string text = read_text(csv);
  return std::count(text.begin(), text.end(), '\n');
}

class SignalTest : public ::testing::TestWithParam<int> {};

TEST_P(SignalTest, StopsWithStatus4AndACheckpointThatContinuesBitwise) {
  ScratchDir dir("signal");
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  const fs::path out = dir / "interrupted";
  ImmerseProcess p(run_args(file, out, small_membrane_sets(kLongRun)), dir / "interrupted_run");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (rows_written(out / "diagnostics.csv") < 1 + kRowsBeforeSignal) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no diagnostics rows written:\n" << p.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  p.signal(GetParam());
  ASSERT_EQ(p.wait(), 4) << p.err();
  const std::string err = p.err();
  EXPECT_NE(err.find("immerse: interrupted by signal " + std::to_string(GetParam()) + " at step "), std::string::npos)
      << err;
  EXPECT_NE(err.find("checkpoint written to " + (out / "checkpoint.h5").string()), std::string::npos) << err;

  // The checkpoint holds the last finished step, which is also the last row of the diagnostics (written once).
  const auto ck = io::Checkpoint::read(out / "checkpoint.h5");
  const long stopped = ck.get_int("step");
  EXPECT_GE(stopped, kRowsBeforeSignal);
  auto rows = read_csv(out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), std::size_t(stopped + 2));  // header, step 0, steps 1..stopped
  EXPECT_EQ(std::stol(rows.back()[0]), stopped);

  // Continue to a nearby end (time.end may change on restart) and compare with one uninterrupted run to it.
  const int end = static_cast<int>(stopped) + kStepsAfterSignal;
  const auto restarted = run_immerse(run_args(file, out, small_membrane_sets(end), out / "checkpoint.h5"),
                                     dir / "restarted_run");
  ASSERT_EQ(restarted.status, 0) << restarted.err;
  const auto whole = run_immerse(run_args(file, dir / "whole", small_membrane_sets(end)), dir / "whole_run");
  ASSERT_EQ(whole.status, 0) << whole.err;
  const auto a = io::Checkpoint::read(dir / "whole" / "checkpoint.h5");
  const auto b = io::Checkpoint::read(out / "checkpoint.h5");
  EXPECT_EQ(b.get_int("step"), end);
  EXPECT_TRUE(a == b) << "checksums " << a.checksum() << " vs " << b.checksum();
  EXPECT_EQ(without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv")),
            without_wall_clock(read_csv(out / "diagnostics.csv")));
}

INSTANTIATE_TEST_SUITE_P(Run, SignalTest, ::testing::Values(SIGTERM, SIGINT),
                         [](const auto& p) { return p.param == SIGTERM ? "SIGTERM" : "SIGINT"; });

}  // namespace
