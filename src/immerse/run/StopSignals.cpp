#include "immerse/run/StopSignals.hpp"

namespace immerse {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_signal(int sig) { g_stop_signal = sig; }

}  // namespace

StopSignals::StopSignals() {
  g_stop_signal = 0;
  for (std::size_t i = 0; i < kSignals.size(); ++i) {
    struct sigaction a {};
    a.sa_handler = kSignals[i] == SIGPIPE ? SIG_IGN : on_signal;
    a.sa_flags = SA_RESTART;
    sigemptyset(&a.sa_mask);
    sigaction(kSignals[i], &a, &saved_[i]);
  }
}

StopSignals::~StopSignals() {
  if (g_stop_signal != 0) return;
  for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &saved_[i], nullptr);
}

int StopSignals::received() { return g_stop_signal; }

}  // namespace immerse
