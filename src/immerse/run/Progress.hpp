#pragma once
// The progress of a run on the log: a bar redrawn after every step on a terminal, otherwise a line every
// output.log_seconds (time, step, steps per second, ETA, the closest approach of a node to a wall).
#include <chrono>
#include <functional>
#include <iosfwd>

namespace immerse {

class SimulationInterface;

class Progress {
 public:
  Progress(std::ostream& out, double end, double log_seconds);
  /// Collective (the closest approach to a wall).
  void update(const SimulationInterface& sim, long steps_done);
  /// The same for a run at `time` and `step`; `wall_distance` gives the closest approach of a node to a wall (not
  /// shown if not finite), asked only when a line is due.
  void update(double time, long step, const std::function<double()>& wall_distance, long steps_done);
  /// Ends the bar's line (on a terminal).
  void finish();

 private:
  using clock = std::chrono::steady_clock;
  std::ostream& out_;
  double end_, every_;
  bool tty_;
  clock::time_point t0_, last_;
};

}  // namespace immerse
