#pragma once
// Where a run's files came from: program version and commit, command line, start time, host and threads. Written
// as comments at the head of config.resolved.toml and as string attributes on the root of every HDF5 file.
#include <string>
#include <utility>
#include <vector>

namespace immerse::io {

/// The commit of the source tree the program was built from ("unknown" outside a git checkout).
std::string build_commit();

struct Provenance {
  std::string version;       ///< program version (IMMERSE_VERSION)
  std::string commit;        ///< build_commit()
  std::string command_line;  ///< as typed, arguments quoted where the shell needs it
  std::string start_time;    ///< UTC, ISO 8601 (2026-12-03T14:05:09Z)
  std::string host;
  std::string threads;       ///< the CPUs available and how the thread count is chosen
  std::string restarted_from;  ///< the checkpoint a restart began from, with its step; empty for a new run

  /// This process now: version, commit, start time and host filled in.
  static Provenance now(std::string command_line, std::string threads);
  /// The command line of `argv` as one shell-quoted line.
  static std::string quote_command_line(int argc, const char* const* argv);

  /// (name, value) pairs for HDF5 attributes: immerse_version, commit, command_line, start_time, host, threads and
  /// (after a restart) restarted_from.
  std::vector<std::pair<std::string, std::string>> attributes() const;
  /// The same as TOML comment lines ("# commit: ...").
  std::string toml_comments() const;
};

}  // namespace immerse::io
