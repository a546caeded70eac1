#include "immerse/run/Progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>

#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

Progress::Progress(std::ostream& out, double end, double log_seconds)
    : out_(out), end_(end), every_(log_seconds), tty_(isatty(STDOUT_FILENO)), t0_(clock::now()), last_(t0_) {}

void Progress::update(const SimulationInterface& sim, long steps_done) {
  // In one process only when the line is printed; over several at every step on every process (a collective call,
  // and only rank 0 decides whether to print).
  if (sim.communicator().size() == 1)
    return update(sim.time(), sim.step(), [&sim] { return sim.min_wall_distance(); }, steps_done);
  const double wall = sim.min_wall_distance();
  update(sim.time(), sim.step(), [wall] { return wall; }, steps_done);
}

void Progress::update(double time, long step, const std::function<double()>& wall_distance, long steps_done) {
  const auto now = clock::now();
  const double elapsed = std::chrono::duration<double>(now - t0_).count();
  if (!tty_ && std::chrono::duration<double>(now - last_).count() < every_) return;
  last_ = now;
  const double frac = std::min(1.0, time / end_), rate = double(steps_done) / std::max(elapsed, 1e-9);
  const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
  std::ostringstream s;
  s << std::setprecision(4) << "t = " << time << " / " << end_ << "  step " << step << "  "
    << rate << " steps/s  ETA " << std::fixed << std::setprecision(0) << eta << " s";
  if (const double wall = wall_distance(); std::isfinite(wall)) s << std::scientific << std::setprecision(3) << "  closest wall approach " << wall;
  if (tty_) {
    const int width = 30, done = static_cast<int>(frac * width);
    out_ << "\r[" << std::string(done, '#') << std::string(width - done, '.') << "] " << s.str() << "   " << std::flush;
  } else {
    out_ << "progress: " << s.str() << "\n" << std::flush;
  }
}

void Progress::finish() {
  if (tty_) out_ << "\n";
}

}  // namespace immerse
