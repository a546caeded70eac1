#pragma once
// Signal dispositions while a run is on: SIGINT, SIGTERM, SIGHUP and SIGQUIT ask for a stop (checkpoint, exit 4);
// SIGPIPE is ignored, so that a closed standard output (`immerse run ... | head`) only silences the log. The
// previous dispositions come back at the end, unless a stop was asked for: then further stop signals (a storm of
// SIGTERM from a scheduler) keep only setting the flag until the program has exited with status 4.
#include <array>
#include <csignal>

namespace immerse {

class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The signal that asked for a stop, 0 if none did.
  static int received();

 private:
  static constexpr std::array<int, 5> kSignals{SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE};
  std::array<struct sigaction, 5> saved_{};
};

}  // namespace immerse
