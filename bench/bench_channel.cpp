// §4.4 whole-run benchmark: 32 red blood cells in the 24 x 48 x 12 um duct (scenarios/rbc_channel.toml: 64x128x32
// grid, 10,242 nodes per cell), the paper's performance claim (JFNK at dt = 4.5e-4 s to t = 0.05 s in 22 min, 43
// times faster than explicit RK2, whose largest stable step was 1.875e-6 s). Measures, in this one run:
//   - JFNK at the scenario's dt to its end time: wall time, fluid solves, Newton and GMRES iterations per step
//     (a rejected attempt's solves count in its step; the adaptive step then advances less than dt, and wall times
//     are scaled by the time actually simulated);
//   - explicit midpoint RK2: its largest stable dt, by bisection on log(dt) with a blow-up test (a run of
//     `probe` steps is unstable when Simulation::advance reports it: a non-finite position or velocity, or a node
//     faster than 4 mm/s, 11 times the empty duct's centre velocity; a slowly growing instability can pass the test,
//     so the bisection can only overestimate the stable step, in the explicit scheme's favour), then its wall time per step over
//     `explicit_steps` steps, scaled to the end time (the full explicit run would take hours; said in the output);
//   - the ratio explicit / implicit of the wall times to the end time, and the peak resident memory;
//   - for each scheme, where the time goes: membrane forces, spreading, fluid, interpolation, the rest (the
//     nonlinear solver's vector work, stability checks), from the operator's timers (StepTimings).
// Usage: bench_channel [--quick] [--jfnk-steps N] [--jfnk-only] [--set key=value ...]
//   --quick         rbc_channel_quick.toml (48 x 96 x 24, 642 nodes per cell) instead of rbc_channel.toml
//   --jfnk-steps N  time N steps of JFNK and scale to the end time (by the time they simulated) instead of running
//                   it all
//   --jfnk-only     skip the explicit scheme
//   --set k=v       as for immerse run, e.g. --set scenario.mu0=1e-3 for stiffer cells
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/simulation/RunSchema.hpp"
#include "immerse/simulation/Scenario.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/timestep/PetscSession.hpp"

using namespace immerse;
using Clock = std::chrono::steady_clock;

namespace {

struct Cost {
  long steps = 0, rejected = 0;
  double seconds = 0, solves = 0, newton = 0, gmres = 0;
  double simulated = 0;  // time advanced (the accepted steps' dt: with rejections they are below the nominal one)
  StepTimings parts;
  double per_step() const { return seconds / double(steps); }
  // Wall time to simulate `span` at this pace.
  double scaled_to(double span) const { return seconds * span / simulated; }
  // Where the time went, per step: membrane forces, spreading, fluid, interpolation, the rest.
  void print_profile(const char* scheme) const {
    std::printf("%s profile, %s\n", scheme, parts.profile(seconds, steps).c_str());
  }
};

std::vector<std::string> g_sets;  // the command line's --set overrides

io::Config channel_config(const std::string& file, const std::string& scheme, double dt, double max_speed = 0.1) {
  std::vector<std::string> sets = g_sets;
  sets.insert(sets.end(), {"time.scheme=" + scheme, "output.fields_every=0", "time.max_speed=" + std::to_string(max_speed)});
  if (dt > 0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "time.dt=%.17g", dt);
    sets.emplace_back(buf);
  }
  return apply_scenario(run_schema().parse_file(file, sets));
}

// Runs `steps` steps (all to the end time when steps <= 0); the first step (no history) is timed too.
Cost run(const io::Config& config, long steps) {
  Simulation sim(config);
  Cost c;
  const StepTimings start = sim.op().timings();
  const auto t0 = Clock::now();
  while (!sim.finished() && (steps <= 0 || c.steps < steps)) {
    const StepRecord r = sim.advance([](const std::string& msg) { std::printf("  %s\n", msg.c_str()); });
    ++c.steps;
    c.rejected += r.rejected;
    c.simulated += r.dt;
    c.solves += double(r.stats.fluid_solves);
    c.newton += double(r.stats.newton_its);
    c.gmres += double(r.stats.gmres_its);
  }
  c.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  c.parts = sim.op().timings().since(start);
  return c;
}

bool rk2_stable(const std::string& file, double dt, long probe) {
  try {
    run(channel_config(file, "rk2", dt, 4e-3), probe);
  } catch (const SimulationError&) {
    return false;
  }
  return true;
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

// The whole benchmark for one scenario file (throws InputError on a bad --set).
int measure(const std::string& file, long jfnk_steps, bool quick, bool jfnk_only);

int main(int argc, char** argv) {
  bool quick = false, jfnk_only = false;
  long jfnk_steps = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    else if (std::strcmp(argv[i], "--jfnk-only") == 0) jfnk_only = true;
    else if (std::strcmp(argv[i], "--jfnk-steps") == 0 && i + 1 < argc) jfnk_steps = std::stol(argv[++i]);
    else if (std::strcmp(argv[i], "--set") == 0 && i + 1 < argc) g_sets.emplace_back(argv[++i]);
    else {
      std::fprintf(stderr, "usage: bench_channel [--quick] [--jfnk-steps N] [--jfnk-only] [--set key=value ...]\n");
      return 2;
    }
  }
  const std::string file =
      std::string(IMMERSE_SOURCE_DIR) + (quick ? "/scenarios/rbc_channel_quick.toml" : "/scenarios/rbc_channel.toml");
  PetscSession petsc;
  try {
    return measure(file, jfnk_steps, quick, jfnk_only);
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_channel: %s\n", e.what());
    return 2;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "bench_channel: the JFNK run stopped: %s\n", e.what());
    return 3;
  }
}

int measure(const std::string& file, long jfnk_steps, bool quick, bool jfnk_only) {
  const io::Config base = channel_config(file, "jfnk", 0);
  const double dt = base.get<double>("time.dt"), T = base.get<double>("time.end");
  std::printf("§4.4 rbc_channel (%s): %lld x %lld x %lld grid, 32 cells of %s level %lld, mu0 = %g N/m, dt = %g s, "
              "t_end = %g s\n",
              file.c_str(), (long long)base.get<int>("grid.nx"), (long long)base.get<int>("grid.ny"),
              (long long)base.get<int>("grid.nz"), base.get<std::string>("membrane[0].mesh.family").c_str(),
              (long long)base.get<int>("membrane[0].mesh.level"), base.get<double>("scenario.mu0"), dt, T);

  const Cost j = run(base, jfnk_steps);
  const double t_jfnk = j.scaled_to(T);
  std::printf("JFNK: %ld steps in %.1f s (%.3f s/step), per step %.2f fluid solves, %.2f Newton, %.2f GMRES%s\n",
              j.steps, j.seconds, j.per_step(), j.solves / double(j.steps), j.newton / double(j.steps),
              j.gmres / double(j.steps), jfnk_steps > 0 ? " (scaled to t_end below)" : "");
  if (j.rejected > 0)
    std::printf("JFNK: %ld attempts rejected (their fluid solves counted above); mean accepted dt %.4g s\n",
                j.rejected, j.simulated / double(j.steps));
  j.print_profile("JFNK");
  std::fflush(stdout);
  if (jfnk_only) {
    std::printf("peak resident memory: %.0f MiB\n", peak_rss_mib());
    return 0;
  }

  // Largest stable RK2 step: bracket [lo stable, hi unstable], then bisect on log(dt).
  const long probe = quick ? 100 : 60;
  double lo = dt / 256, hi = dt / 8;
  while (rk2_stable(file, hi, probe) && hi < dt) lo = hi, hi *= 4;
  while (!rk2_stable(file, lo, probe)) hi = lo, lo /= 4;
  for (int it = 0; it < 5; ++it) {
    const double mid = std::sqrt(lo * hi);
    (rk2_stable(file, mid, probe) ? lo : hi) = mid;
    std::printf("  RK2 bracket [%.4g, %.4g] s\n", lo, hi);
    std::fflush(stdout);
  }
  const long explicit_steps = quick ? 40 : 20;
  const Cost e = run(channel_config(file, "rk2", lo), explicit_steps);
  const double t_explicit = e.scaled_to(T);
  std::printf("RK2: largest stable dt = %.4g s (paper: 1.875e-6; %ld-step blow-up test), %.3f s/step, %.2f fluid "
              "solves/step; %.0f steps to t_end\n",
              lo, probe, e.per_step(), e.solves / double(e.steps), T / lo);
  e.print_profile("RK2");
  std::printf("wall time to t = %g s: JFNK %.1f s%s, explicit RK2 %.1f s (from %ld timed steps, scaled)\n", T, t_jfnk,
              jfnk_steps > 0 ? " (scaled)" : "", t_explicit, explicit_steps);
  std::printf("ratio explicit / implicit: %.1f (paper: 43)\n", t_explicit / t_jfnk);
  std::printf("peak resident memory: %.0f MiB\n", peak_rss_mib());
  return 0;
}
