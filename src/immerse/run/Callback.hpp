#pragma once
// Scheduled work around the time loop (Oceananigans' Callback + IterationInterval): output and diagnostics are
// callbacks with a schedule, not modulo checks in the loop.
#include <functional>
#include <string>

namespace immerse {

class SimulationInterface;

struct Callback {
  std::string name;
  long every = 1;  ///< run after every `every`-th step (0: never during the run)
  bool at_start = false;  ///< also run before the first step
  bool at_end = false;    ///< also run after the last step (if the last step was not already scheduled)
  std::function<void(const SimulationInterface&)> act;
  long last_step = -1;  ///< step at which it last ran

  bool due(long step) const { return every > 0 && step % every == 0; }
  void run(const SimulationInterface& sim, long step) {
    act(sim);
    last_step = step;
  }
};

}  // namespace immerse
