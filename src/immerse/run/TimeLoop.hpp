#pragma once
// The time loop of `immerse run`, in one process or many: steps until time.end, the scenario's end or a stop signal
// (received by any process: the processes agree after each step), with the scenario's work and the output callbacks
// after each step, and turns what ended the run into its exit status. The last state is
// always saved, unless writing is what failed: after an instability to unstable_state.h5, for inspection, leaving
// checkpoint.h5 at the last good step (UnstableStop.hpp).
#include <iosfwd>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/run/Callback.hpp"
#include "immerse/run/OutputSchedule.hpp"
#include "immerse/run/OutputWriter.hpp"
#include "immerse/run/Progress.hpp"
#include "immerse/scenario/ScenarioRun.hpp"
#include "immerse/simulation/SimulationInterface.hpp"
#include "immerse/simulation/StepTimings.hpp"

namespace immerse {

class TimeLoop {
 public:
  /// `out` and `err`: rank 0's log streams (streams that drop what they are given on the other processes).
  TimeLoop(SimulationInterface& sim, ScenarioRun& scenario, OutputWriter& output, const OutputSchedule& settings, std::ostream& out,
           std::ostream& err);
  TimeLoop(const TimeLoop&) = delete;
  TimeLoop& operator=(const TimeLoop&) = delete;

  /// Runs the loop; returns the exit status of run_command (0, 3, 4 or 5). Bad input found only once the run is on
  /// (InputError) removes the run's files (OutputWriter::discard) and passes through.
  int run();

  /// Steps taken, the wall time spent in advance() (failed calls included), and its parts on this process.
  long steps() const { return steps_; }
  double stepping_seconds() const { return stepping_; }
  StepTimings timings() const { return sim_.timings().since(timings_at_start_); }

 private:
  void step_once();
  void log(const std::string& message);
  void write_failed(const WriteError& e);
  /// Whether any process received a stop signal (its number kept for the last line). Collective.
  bool stop_signal();

  SimulationInterface& sim_;
  ScenarioRun& scenario_;
  OutputWriter& output_;
  std::ostream& out_;
  std::ostream& err_;
  StepRecord last_;  ///< of the last accepted step (the diagnostics rows report it)
  std::vector<Callback> callbacks_;
  Progress progress_;
  int status_ = 0, signal_ = 0;
  long steps_ = 0;
  double stepping_ = 0;
  StepTimings timings_at_start_;
};

}  // namespace immerse
