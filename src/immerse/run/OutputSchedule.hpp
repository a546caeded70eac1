#pragma once
// The settings of `immerse run` around the time loop (output.*, time.end), read once from the resolved
// configuration.
#include "immerse/io/Config.hpp"

namespace immerse {

struct OutputSchedule {
  long diagnostics_every = 1;  ///< output.diagnostics_every: steps between rows of diagnostics.csv
  long fields_every = 0;       ///< output.fields_every: steps between ParaView frames (0: none)
  long checkpoint_every = 0;   ///< output.checkpoint_every: steps between checkpoints (0: only at the end)
  bool fluid_fields = true;    ///< output.fluid_fields: the fluid in the frames
  double end_time = 0;         ///< time.end (s)
  double log_seconds = 10;     ///< output.log_seconds: wall-clock seconds between log lines when not on a terminal

  static OutputSchedule from(const io::Config& config);
};

}  // namespace immerse
