#pragma once
// The command line of `immerse run`.
#include <filesystem>
#include <string>
#include <vector>

namespace immerse {

struct CommandLine {
  std::filesystem::path file;
  std::vector<std::string> sets;
  std::filesystem::path out = "out";
  std::filesystem::path restart;  ///< empty: start from t = 0
  bool overwrite = false;         ///< remove the run files of another run in `out` first
  bool verbose = false;           ///< print the whole resolved configuration before the run
  std::string command_line;       ///< recorded in the run folder (Provenance); "immerse run FILE" if empty
  std::string program = "immerse";  ///< as started (argv[0]), for the commands a stopped run suggests
};

}  // namespace immerse
