#pragma once
// What a run stopped by an instability (exit 3) leaves and says last: checkpoint.h5 stays the last checkpoint written
// at a good step (the unstable state goes to unstable_state.h5 beside it), and one line names the checkpoint kept,
// its step and time, and the command that continues from it with half the time step.
#include <filesystem>
#include <string>

#include "immerse/io/Config.hpp"
#include "immerse/run/CommandLine.hpp"

namespace immerse {

/// The post-mortem file of a run stopped by an instability, beside its checkpoint.
inline std::filesystem::path unstable_state_file(const std::filesystem::path& dir) { return dir / "unstable_state.h5"; }

/// Where a run that became unstable can continue from.
struct KeptCheckpoint {
  std::filesystem::path file;  ///< empty: no checkpoint (the run starts again from t = 0)
  long step = 0;
  double time = 0;
  bool in_out = true;  ///< in the run's own folder (else the checkpoint a branched run began from)
};

/// The last line of a run stopped by an instability at `step`: the checkpoint kept and the command (run over
/// `processes` MPI processes) that continues from it with half of time.step (scenario.k_dt when time.dt was derived
/// from it); `unstable_written`: whether the state it stopped in was saved to unstable_state.h5.
std::string unstable_stop_line(const CommandLine& options, const io::Config& config, const KeptCheckpoint& kept,
                               long step, bool unstable_written, int processes = 1);

}  // namespace immerse
