// §4.1 whole-run benchmark (issue: JFNK vs explicit at the paper's size): the oscillating membrane on a 64^3 grid
// with 16,386 membrane nodes. Measures, in this one run:
//   - JFNK at dt = dx and dt = 4dx: wall time per step, fluid solves per step (Newton + GMRES iterations);
//   - forward Euler: its largest stable dt, found by bisection on dt/dx with a blow-up test (a run of
//     `probe_steps` steps is unstable when a node leaves the box, goes beyond r = 0.45 from the centre, or a
//     velocity becomes non-finite), and its wall time per step;
//   - the ratio of the wall times to reach t = 10: explicit (t/dt_stable steps) over JFNK at dt = 4dx.
// Usage: bench_oscillating [--quick]   (--quick: 32^3 grid, 1,026 nodes)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "immerse/core/Error.hpp"
#include "immerse/timestep/PetscSession.hpp"
#include "immerse/verify/OscillatingMembrane.hpp"

using namespace immerse;
using Clock = std::chrono::steady_clock;

namespace {

struct Cost {
  double seconds_per_step = 0, solves_per_step = 0, newton = 0, gmres = 0;
};

Cost measure(const char* scheme, int n, int level, double dt, int steps) {
  verify::OscillatingMembrane exp(n, level, 0.01);
  auto integ = make_integrator(scheme, {});
  integ->step(exp.op(), dt);  // the first step (no history) is not typical
  const std::size_t solves0 = exp.op().fluid_solves();
  Cost c;
  const auto t0 = Clock::now();
  for (int k = 0; k < steps; ++k) {
    const auto st = integ->step(exp.op(), dt);
    if (!st.converged) throw SimulationError(std::string(scheme) + ": step failed: " + st.failure);
    c.newton += st.newton_its;
    c.gmres += st.gmres_its;
  }
  c.seconds_per_step = std::chrono::duration<double>(Clock::now() - t0).count() / steps;
  c.solves_per_step = double(exp.op().fluid_solves() - solves0) / steps;
  c.newton /= steps;
  c.gmres /= steps;
  return c;
}

bool euler_stable(int n, int level, double dt, int probe_steps) {
  verify::OscillatingMembrane exp(n, level, 0.01);
  auto euler = make_integrator("euler", {});
  try {
    for (int k = 0; k < probe_steps; ++k) {
      euler->step(exp.op(), dt);
      const auto X = exp.op().positions();
      for (std::size_t i = 0; i < X.size(); i += 3)
        if (!(std::hypot(X[i] - 0.5, X[i + 1] - 0.5, X[i + 2] - 0.5) < 0.45)) return false;
    }
  } catch (const SimulationError&) {
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const int n = quick ? 32 : 64, level = quick ? 3 : 5, steps = quick ? 10 : 5;
  const double h = 1.0 / n, T = 10.0;
  PetscSession petsc;
  std::printf("§4.1 oscillating membrane, %d^3 grid, octahedral level %d, mu = 0.01\n", n, level);
  const Cost j1 = measure("jfnk", n, level, h, steps), j4 = measure("jfnk", n, level, 4 * h, steps);
  std::printf("%-28s %12s %14s %10s %10s\n", "scheme", "s/step", "fluid solves", "Newton", "GMRES");
  std::printf("%-28s %12.4f %14.2f %10.2f %10.2f\n", "JFNK, dt = dx", j1.seconds_per_step, j1.solves_per_step,
              j1.newton, j1.gmres);
  std::printf("%-28s %12.4f %14.2f %10.2f %10.2f\n", "JFNK, dt = 4dx", j4.seconds_per_step, j4.solves_per_step,
              j4.newton, j4.gmres);
  // Largest stable forward-Euler step by bisection on log(dt) between a stable and an unstable bracket.
  const int probe = quick ? 200 : 100;
  double lo = h / 64, hi = 4 * h;
  while (!euler_stable(n, level, lo, probe)) lo /= 4;
  for (int it = 0; it < 6; ++it) {
    const double mid = std::sqrt(lo * hi);
    (euler_stable(n, level, mid, probe) ? lo : hi) = mid;
  }
  const Cost e = measure("euler", n, level, lo, steps);
  std::printf("%-28s %12.4f %14.2f   (largest stable dt = %.3g = dx/%.1f, %d-step blow-up test)\n",
              "forward Euler, stable dt", e.seconds_per_step, e.solves_per_step, lo, h / lo, probe);
  const double t_explicit = e.seconds_per_step * T / lo, t_jfnk = j4.seconds_per_step * T / (4 * h);
  std::printf("time to t = 10 (from the per-step costs): explicit %.1f s, JFNK (dt = 4dx) %.1f s\n", t_explicit, t_jfnk);
  std::printf("ratio explicit / JFNK: %.1f\n", t_explicit / t_jfnk);
  return 0;
}
