#pragma once
// `immerse run FILE.toml [--set key=value ...] [--out DIR] [--restart CHECKPOINT] [--overwrite]`: reads and validates
// the whole configuration and builds the run before anything is written; then prints and saves the resolved
// configuration, runs the time loop with its scheduled callbacks (diagnostics.csv, ParaView frames, checkpoints,
// progress), and stops cleanly on instability or SIGINT/SIGTERM/SIGHUP/SIGQUIT with a last checkpoint and frame.
// The output folder is locked while the run writes, and a folder holding another run is refused unless continued or
// replaced.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace immerse {

struct RunOptions {
  std::filesystem::path file;
  std::vector<std::string> sets;
  std::filesystem::path out = "out";
  std::filesystem::path restart;  ///< empty: start from t = 0
  bool overwrite = false;         ///< remove the run files of another run in `out` first
  bool verbose = false;           ///< print the whole resolved configuration before the run
  std::string command_line;       ///< recorded in the run folder (Provenance); "immerse run FILE" if empty
};

/// Exit status: 0 done, 2 bad input (nothing written), 3 the run became unstable, 4 interrupted by a signal,
/// 5 an output file could not be written during the run (full disk; no further write, earlier files complete).
int run_command(const RunOptions& options, std::ostream& out, std::ostream& err);

/// Prints the bundled scenarios (scenarios/*.toml) with the first comment line of each.
void list_scenarios(const std::filesystem::path& dir, std::ostream& out);

/// Prints every configuration key with its default, allowed values and doc string.
void print_config_help(std::ostream& out);

}  // namespace immerse
