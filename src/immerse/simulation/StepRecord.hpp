#pragma once
#include "immerse/timestep/SolverStats.hpp"

namespace immerse {

/// What one accepted step did (one row of diagnostics.csv before the membrane columns).
struct StepRecord {
  long step = 0;
  double time = 0, dt = 0;
  SolverStats stats;
  int rejected = 0;
  double wall_seconds = 0;
};

}  // namespace immerse
