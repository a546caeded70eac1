#pragma once
// `immerse run FILE.toml [--set key=value ...] [--out DIR] [--restart CHECKPOINT] [--overwrite]`: reads and validates
// the whole configuration and builds the run before anything is written; then saves the resolved configuration and
// runs the time loop with its output on schedules (OutputWriter, TimeLoop). It stops cleanly on instability or a stop
// signal (StopSignals) with a last checkpoint and frame.
#include <filesystem>
#include <iosfwd>

#include "immerse/run/CommandLine.hpp"

namespace immerse {

/// `out` and `err` are written by rank 0 only when the program runs over several MPI processes (run_distributed).
/// Exit status: 0 done, 2 bad input (nothing written), 3 the run became unstable, 4 interrupted by a signal,
/// 5 an output file could not be written during the run (full disk; no further write, earlier files complete).
int run_command(const CommandLine& options, std::ostream& out, std::ostream& err);

/// InputError for an empty --out or a --restart naming a folder.
void check_run_paths(const CommandLine& options);

/// Prints the bundled scenarios (scenarios/*.toml) with the first comment line of each.
void list_scenarios(const std::filesystem::path& dir, std::ostream& out);

/// Prints every configuration key with its default, allowed values and doc string.
void print_config_help(std::ostream& out);

}  // namespace immerse
