#pragma once
// What a restart checks in a checkpoint before it uses it, shared by Simulation and DistributedSimulation: that the
// checkpoint was written by this configuration (up to the keys a continued or branched run may change), and each
// entry's presence, size and finiteness, so that a damaged checkpoint whose checksum was recomputed is refused by
// name (InputError) instead of failing later in the run.
#include <cstdint>
#include <string>
#include <vector>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"

namespace immerse {

/// InputError naming the first key whose value differs from the checkpoint's configuration (time.end, time.dt,
/// time.dt_min, scenario.kt_end, scenario.k_dt, [output] and [solver] keys and the names of mesh files may differ).
void check_checkpoint_configuration(const io::Config& config, const io::Checkpoint& ck);

/// The step the run continues with: the checkpoint's stepper.dt (InputError unless in (0, time.dt] of the
/// checkpoint's own configuration), at most time.dt of `config` (a restart may take a smaller step).
double continued_step(const io::Config& config, const io::Checkpoint& ck);

/// The checked getters of one checkpoint.
class CheckpointEntries {
 public:
  explicit CheckpointEntries(const io::Checkpoint& ck) : ck_(ck) {}
  /// An integer >= 0.
  std::int64_t count(const std::string& name) const;
  /// A finite number >= 0.
  double time_value(const std::string& name) const;
  /// An array of `size` finite values.
  const std::vector<double>& array(const std::string& name, std::size_t size) const;
  /// `v` if `ok`, else InputError "checkpoint SOURCE: NAME = V: must be ALLOWED".
  double number(const std::string& name, double v, bool ok, const std::string& allowed) const;

 private:
  const io::Checkpoint& ck_;
};

}  // namespace immerse
