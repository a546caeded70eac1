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
  while (rows_written(out / "diagnostics.csv") < 1 + kRowsBeforeSignal) {
    ASSERT_LT(p.try_wait(), 0) << "the run ended before writing its diagnostics rows:\n" << p.err();
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

INSTANTIATE_TEST_SUITE_P(Run, SignalTest, ::testing::Values(SIGTERM, SIGINT, SIGHUP, SIGQUIT), [](const auto& p) {
  return p.param == SIGTERM ? "SIGTERM" : p.param == SIGINT ? "SIGINT" : p.param == SIGHUP ? "SIGHUP" : "SIGQUIT";
});

/// Waits until `csv` holds the header and `rows` rows, however long that takes (a run that ends before: a failed
/// expectation).
void wait_for_rows(ImmerseProcess& p, const fs::path& csv, std::size_t rows) {
  while (rows_written(csv) < 1 + rows) {
    ASSERT_LT(p.try_wait(), 0) << "the run ended before writing its diagnostics rows:\n" << p.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

// SIGTERM every few milliseconds from the first rows to the end, so that some arrive while the checkpoint is
// written and while the program finishes: it still ends with status 4 and a checkpoint that reads back.
TEST(SignalStorm, RepeatedSigtermStillEndsWithStatus4AndAValidCheckpoint) {
  ScratchDir dir("signal");
  const fs::path out = dir / "out";
  ImmerseProcess p(run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(kLongRun)),
                   dir / "run");
  wait_for_rows(p, out / "diagnostics.csv", kRowsBeforeSignal);
  int status = -1;
  while (status < 0) {  // until the program ends
    p.signal(SIGTERM);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    status = p.try_wait();
  }
  ASSERT_EQ(status, 4) << p.err();
  const auto ck = io::Checkpoint::read(out / "checkpoint.h5");
  EXPECT_EQ(std::stol(read_csv(out / "diagnostics.csv").back()[0]), ck.get_int("step"));
}

// A step that is rejected and halved again and again (one Newton iteration allowed, a tolerance no iterate meets):
// a SIGTERM stops it between two attempts, without waiting for the step to be accepted; the checkpoint holds the
// last accepted state (step 0).
TEST(SignalHalving, StopRequestIsHonouredBetweenAttemptsOfAHalvedStep) {
  ScratchDir dir("signal");
  const fs::path out = dir / "out";
  auto sets = small_membrane_sets(8);
  sets.insert(sets.end(), {"solver.max_newton_its=1", "solver.newton_rtol=1e-300", "time.dt_min=1e-300"});
  ImmerseProcess p(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets), dir / "run");
  while (p.out().find("step 1, t = 0: step rejected with dt = ") == std::string::npos) {
    ASSERT_LT(p.try_wait(), 0) << "the run ended without a rejected step:\n" << p.out() << p.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  p.signal(SIGTERM);
  ASSERT_EQ(p.wait(), 4) << p.err();
  EXPECT_NE(p.err().find("immerse: interrupted by signal 15 at step 0, t = 0; checkpoint written to"), std::string::npos)
      << p.err();
  EXPECT_EQ(io::Checkpoint::read(out / "checkpoint.h5").get_int("step"), 0);
}

// A second run into the folder of a run that is still writing is refused (one line, status 2) and changes nothing.
TEST(SignalConcurrent, SecondRunIntoAFolderInUseIsRefused) {
  ScratchDir dir("signal");
  const fs::path out = dir / "out";
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  ImmerseProcess first(run_args(file, out, small_membrane_sets(kLongRun)), dir / "first");
  wait_for_rows(first, out / "diagnostics.csv", 1);
  const std::string config = read_text(out / "config.resolved.toml");
  auto args = run_args(file, out, small_membrane_sets(1));
  args.push_back("--overwrite");  // not even a replacement is allowed while the folder is in use
  const auto second = run_immerse(args, dir / "second");
  EXPECT_EQ(second.status, 2) << second.err;
  EXPECT_EQ(second.err, "immerse: error: --out " + out.string() +
                            " is in use by another immerse run (one run per output folder; wait for it or choose "
                            "another --out)\n");
  EXPECT_EQ(second.out, "");
  EXPECT_EQ(read_text(out / "config.resolved.toml"), config);
  first.signal(SIGTERM);
  EXPECT_EQ(first.wait(), 4) << first.err();
}

// Standard output closed by its reader (`immerse run ... | head -1`): the run goes on without it, with no report
// of a broken pipe, and ends normally.
TEST(SignalPipe, ClosedStandardOutputDoesNotStopTheRun) {
  ScratchDir dir("signal");
  const fs::path out = dir / "out";
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  close(fds[0]);
  ImmerseProcess p(run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(3)), dir / "run",
                   {}, fds[1]);
  close(fds[1]);
  EXPECT_EQ(p.wait(), 0) << p.err();
  EXPECT_EQ(p.err(), "");
  EXPECT_EQ(io::Checkpoint::read(out / "checkpoint.h5").get_int("step"), 3);
}

// `immerse verify NAME | head -1` with the reader gone before the first line: the study runs to its verdict (exit 0,
// all pass) instead of the program dying by SIGPIPE.
TEST(SignalPipe, ClosedStandardOutputDoesNotKillAVerification) {
  ScratchDir dir("signal");
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  close(fds[0]);
  ImmerseProcess p({"verify", "fluid_divergence", "--quick"}, dir / "verify", {}, fds[1]);
  close(fds[1]);
  EXPECT_EQ(p.wait(), 0) << p.err();
  EXPECT_EQ(p.err(), "");
}

// A stop asked for while [packing] places the cells (59 red cells at H = 0.4 in the quick suspension take minutes
// to place) ends the run at once with status 4, one line, and nothing written. The signal is sent once the run
// catches it, however long its start takes.
TEST(SignalPacking, StopWhilePackingEndsAtOnceWithStatus4AndNothingWritten) {
  ScratchDir dir("signal");
  const fs::path out = dir / "out";
  ImmerseProcess p(run_args(scenario_file("suspension_shear_quick.toml"), out, {"packing.volume_fraction=0.4"}),
                   dir / "run");
  while (!catches_sigterm(p.pid())) {
    ASSERT_LT(p.try_wait(), 0) << "the run ended before the signal:\n" << p.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const auto sent = std::chrono::steady_clock::now();
  p.signal(SIGTERM);
  ASSERT_EQ(p.wait(), 4) << p.err();
  EXPECT_LT(std::chrono::steady_clock::now() - sent, std::chrono::seconds(60));  // the packing alone takes minutes
  EXPECT_EQ(p.err(), "immerse: interrupted by signal 15 while packing the cells, before the first step; nothing "
                     "written\n");
  EXPECT_FALSE(fs::exists(out));
}
