// §4.4 whole-run benchmark: 32 red blood cells in the 24 x 48 x 12 um duct (scenarios/rbc_channel.toml: 64x128x32
// grid, 10,242 nodes per cell), the paper's performance claim (JFNK at dt = 4.5e-4 s to t = 0.05 s in 22 min, 43
// times faster than explicit RK2, whose largest stable step was 1.875e-6 s). Measures, in this one run:
//   - the implicit scheme (JFNK, or each scheme --implicit lists) at the scenario's dt to its end time: wall time,
//     fluid solves, nonlinear (Newton or Anderson) and GMRES iterations per step (a rejected attempt's solves count
//     in its step; the adaptive step then advances less than dt, and wall times are scaled by the time actually
//     simulated);
//   - explicit midpoint RK2: its largest stable dt, the largest step at which a run reaches the end time without a
//     blow-up (Simulation::advance reports a non-finite position or velocity, or a node faster than 4 mm/s, 11 times
//     the empty duct's centre velocity). Every probe runs to the end time: the scheme's instability can grow for
//     hundreds of steps before it shows. From dt/8 (or --rk2-from) the probes halve the step until one reaches the
//     end time, then bisect on log(dt) three times. While halving, a probe runs until it blows up, reaches the end
//     time or spends the rest of the budget (--rk2-budget): an unstable step shows well before the end, so even a
//     probe whose full run cannot fit may lower the bound (stiff cells); the later probes are started only if their
//     full run fits into the budget at the pace measured so far. The explicit wall time is the full run at the
//     largest stable step found; if none was found within the budget, the output says so and gives bounds: the
//     stable step lies below the smallest one tried, so the explicit run takes more than its step count times the
//     measured time per step;
//   - the ratio explicit / implicit of the wall times to the end time (for each implicit scheme), and the peak
//     resident memory;
//   - what sets the ratio: an implicit step's residual evaluations (each a force evaluation, spreading, a fluid step
//     and an interpolation) and its other work against an RK2 step, and the ratio with no other work, with three
//     evaluations per step (a Newton step's least at the paper's tolerance) and the evaluations 43 would allow;
//   - for each scheme, where the time goes: membrane forces, spreading, fluid, interpolation, the rest (the
//     nonlinear solver's vector work, stability checks), from the operator's timers (StepTimings).
// Usage: bench_channel [--quick] [--implicit S,...] [--jfnk-steps N] [--jfnk-only] [--rk2-budget S] [--rk2-from DT]
//                      [--set key=value ...]
//   --quick         rbc_channel_quick.toml (48 x 96 x 24, 642 nodes per cell) instead of rbc_channel.toml
//   --implicit S,.. the implicit schemes to time, each against the same explicit run: jfnk (default, the paper's),
//                   anderson, lbfgs
//   --jfnk-steps N  time N steps of each implicit scheme and scale to the end time (by the time they simulated)
//                   instead of running it all
//   --jfnk-only     skip the explicit scheme
//   --rk2-budget S  wall-clock seconds for the explicit probes (default 3600)
//   --rk2-from DT   the first explicit probe's step (default dt/8)
//   --set k=v       as for immerse run, e.g. --set scenario.mu0=1e-3 for stiffer cells
#include <sys/resource.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
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
  sets.insert(sets.end(),
              {"time.scheme=" + scheme, "output.fields_every=0", "time.max_speed=" + std::to_string(max_speed)});
  if (dt > 0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "time.dt=%.17g", dt);
    sets.emplace_back(buf);
  }
  return apply_scenario(run_schema().parse_file(file, sets));
}

// Advances `sim` by `steps` steps (to its end time when steps <= 0; the first step, without history, is timed too),
// or until `budget_s` seconds of wall time have passed, adding to `c`. A blow-up propagates as SimulationError, with
// what was run until then accounted in `c`.
void run(Simulation& sim, long steps, double budget_s, Cost& c) {
  const StepTimings start = sim.op().timings();
  const auto t0 = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  const auto account = [&] {
    c.seconds = elapsed();
    c.parts = sim.op().timings().since(start);
  };
  try {
    while (!sim.finished() && (steps <= 0 || c.steps < steps) && elapsed() < budget_s) {
      const StepRecord r = sim.advance([](const std::string& msg) { std::printf("  %s\n", msg.c_str()); });
      ++c.steps;
      c.rejected += r.rejected;
      c.simulated += r.dt;
      c.solves += double(r.stats.fluid_solves);
      c.newton += double(r.stats.newton_its);
      c.gmres += double(r.stats.gmres_its);
    }
  } catch (const SimulationError&) {
    account();
    throw;
  }
  account();
}

Cost run(const io::Config& config, long steps) {
  Simulation sim(config);
  Cost c;
  run(sim, steps, std::numeric_limits<double>::infinity(), c);
  return c;
}

// An explicit RK2 run at dt towards the end time: stable when it gets there, unstable when Simulation::advance
// reports a blow-up first (a non-finite value or a node faster than 4 mm/s), undecided when `budget_s` seconds of
// wall time end first.
struct Probe {
  enum Outcome { stable, unstable, undecided } outcome = undecided;
  double dt = 0, reached = 0;  // the step and the time the run reached
  std::string why;             // the blow-up, as Simulation::advance reported it
  Cost cost;
};

Probe rk2_probe(const std::string& file, double dt, double budget_s) {
  Simulation sim(channel_config(file, "rk2", dt, 4e-3));
  Probe p;
  p.dt = dt;
  try {
    run(sim, 0, budget_s, p.cost);
    p.outcome = sim.finished() ? Probe::stable : Probe::undecided;
  } catch (const SimulationError& e) {
    p.outcome = Probe::unstable;
    p.why = e.what();
  }
  p.reached = sim.time();
  const char* what[] = {"reached t_end", "blew up", "undecided (budget spent)"};
  std::printf("  RK2 dt = %.4g s: %s at t = %.4g s after %ld steps, %.1f s (%.3f s/step)%s%s\n", dt, what[p.outcome],
              p.reached, p.cost.steps, p.cost.seconds, p.cost.per_step(), p.why.empty() ? "" : ": ", p.why.c_str());
  std::fflush(stdout);
  return p;
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

// The whole benchmark for one scenario file (throws InputError on a bad --set).
int measure(const std::string& file, const std::vector<std::string>& implicit, long jfnk_steps, bool jfnk_only,
            double rk2_budget, double rk2_from);

int main(int argc, char** argv) {
  bool quick = false, jfnk_only = false;
  long jfnk_steps = 0;
  double rk2_budget = 3600, rk2_from = 0;
  std::vector<std::string> implicit{"jfnk"};
  CLI::App app{"§4.4 whole-run benchmark: the implicit schemes against explicit RK2 (bench/bench_channel.cpp)"};
  app.add_flag("--quick", quick, "rbc_channel_quick.toml (48 x 96 x 24, 642-node cells) instead of rbc_channel.toml");
  app.add_option("--implicit", implicit, "implicit schemes to time against the explicit run, comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember({"jfnk", "anderson", "lbfgs"}))
      ->capture_default_str();
  app.add_option("--jfnk-steps", jfnk_steps,
                 "time N steps of each implicit scheme and scale to the end time (0: the whole run)");
  app.add_flag("--jfnk-only", jfnk_only, "skip the explicit scheme");
  app.add_option("--rk2-budget", rk2_budget, "wall-clock seconds for the explicit probes (> 0)")->capture_default_str();
  app.add_option("--rk2-from", rk2_from, "the first explicit probe's step (s, > 0; default dt/8)");
  app.add_option("--set", g_sets, "key=value, as for immerse run (repeatable)");
  try {
    app.parse(argc, argv);
    if (jfnk_steps < 0) throw CLI::ValidationError("--jfnk-steps", "must be >= 0");
    if (!(rk2_budget > 0)) throw CLI::ValidationError("--rk2-budget", "must be > 0");
    if (app.count("--rk2-from") && !(rk2_from > 0)) throw CLI::ValidationError("--rk2-from", "must be > 0");
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::fprintf(stderr, "bench_channel: error: %s (see bench_channel --help)\n", e.what());
    return 2;
  }
  const std::string file =
      std::string(IMMERSE_SOURCE_DIR) + (quick ? "/scenarios/rbc_channel_quick.toml" : "/scenarios/rbc_channel.toml");
  PetscSession petsc;
  try {
    return measure(file, implicit, jfnk_steps, jfnk_only, rk2_budget, rk2_from);
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_channel: %s\n", e.what());
    return 2;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "bench_channel: the implicit run stopped: %s\n", e.what());
    return 3;
  }
}

int measure(const std::string& file, const std::vector<std::string>& implicit, long jfnk_steps, bool jfnk_only,
            double rk2_budget, double rk2_from) {
  const io::Config base = channel_config(file, implicit.front(), 0);
  const double dt = base.get<double>("time.dt"), T = base.get<double>("time.end");
  std::printf("§4.4 rbc_channel (%s): %lld x %lld x %lld grid, 32 cells of %s level %lld, mu0 = %g N/m, dt = %g s, "
              "t_end = %g s\n",
              file.c_str(), (long long)base.get<int>("grid.nx"), (long long)base.get<int>("grid.ny"),
              (long long)base.get<int>("grid.nz"), base.get<std::string>("membrane[0].mesh.family").c_str(),
              (long long)base.get<int>("membrane[0].mesh.level"), base.get<double>("scenario.mu0"), dt, T);

  struct Timed {
    std::string label;
    double to_end;          // wall time to t_end
    double steps_to_end;    // at the mean accepted step
    double evaluation;      // seconds per residual evaluation: forces, spreading, fluid step, interpolation
    double solves;          // residual evaluations (fluid solves) per step
    double other;           // seconds per step outside the evaluations: the solver's own work, guess, checks
  };
  std::vector<Timed> timed;
  for (const std::string& scheme : implicit) {
    const std::string label = scheme == "jfnk" ? "JFNK" : scheme == "anderson" ? "Anderson" : "L-BFGS";
    const Cost j = [&] {
      try {
        return run(channel_config(file, scheme, 0), jfnk_steps);
      } catch (const SimulationError& e) {
        throw SimulationError(label + ": " + e.what());
      }
    }();
    timed.push_back({label, j.scaled_to(T), T / (j.simulated / double(j.steps)), j.parts.total() / j.solves,
                     j.solves / double(j.steps), (j.seconds - j.parts.total()) / double(j.steps)});
    std::printf("%s: %ld steps in %.1f s (%.3f s/step), per step %.2f fluid solves, %.2f %s, %.2f GMRES%s\n",
                label.c_str(), j.steps, j.seconds, j.per_step(), j.solves / double(j.steps),
                j.newton / double(j.steps), scheme == "jfnk" ? "Newton" : "nonlinear iterations",
                j.gmres / double(j.steps), jfnk_steps > 0 ? " (scaled to t_end below)" : "");
    if (j.rejected > 0)
      std::printf("%s: %ld attempts rejected (their fluid solves counted above); mean accepted dt %.4g s\n",
                  label.c_str(), j.rejected, j.simulated / double(j.steps));
    j.print_profile(label.c_str());
    std::fflush(stdout);
  }
  if (jfnk_only) {
    std::printf("peak resident memory: %.0f MiB\n", peak_rss_mib());
    return 0;
  }

  // Largest step at which explicit RK2 reaches t_end. Its instability can grow slowly (at the paper's size a node
  // runs away after 64 steps at dt = 8.3e-5 s, after 654 at 1.5e-5 s), so every probe runs to t_end: from dt/8,
  // halved until a probe gets there (doubled while it does, if the first does), then bisected on log(dt). While
  // halving, a probe runs with whatever is left of the budget even when its full run cannot fit: a blow-up within
  // it still lowers the bound (at mu0 = 1 mN/m RK2 runs away after 61 steps at 1.3e-6 s and after 624 at 6.5e-7 s,
  // where a full run is 38,000 and 77,000 steps). The other probes are started only if their full run fits into
  // what is left of the budget at the pace measured so far.
  const auto start = Clock::now();
  const auto left = [&] { return rk2_budget - std::chrono::duration<double>(Clock::now() - start).count(); };
  double spent = 0, stepped = 0;  // RK2's wall time and steps so far
  const auto fits = [&](double d) { return stepped == 0 || T / d * (spent / stepped) <= left(); };
  std::optional<Probe> lo, hi;  // the largest step found stable, the smallest found unstable
  const auto probe = [&](double d, bool needs_full_run) {
    if (left() <= 0 || (needs_full_run && !fits(d))) return false;
    Probe p = rk2_probe(file, d, left());
    spent += p.cost.seconds;
    stepped += double(p.cost.steps);
    if (p.outcome == Probe::undecided) return false;
    (p.outcome == Probe::stable ? lo : hi) = p;
    return true;
  };
  for (double d = rk2_from > 0 ? rk2_from : dt / 8; !lo; d /= 2)  // down until a probe reaches t_end
    if (!probe(d, false)) break;
  if (lo)  // up while probes reach it (when the first did)
    for (double d = 2 * lo->dt; !hi && d < dt; d *= 2)
      if (!probe(d, true)) break;
  for (int it = 0; it < 3 && lo && hi; ++it)
    if (!probe(std::sqrt(lo->dt * hi->dt), true)) break;

  const char* scaled = jfnk_steps > 0 ? " (scaled)" : "";
  if (lo) {
    char above[96] = "no larger step was found to blow up: the largest stable step may be larger";
    if (hi) std::snprintf(above, sizeof above, "%.4g s blows up (at t = %.4g s)", hi->dt, hi->reached);
    std::printf("RK2: largest stable dt = %.4g s (paper: 1.875e-6): reaches t_end in %ld steps, %.3f s/step, %.2f "
                "fluid solves/step; %s\n",
                lo->dt, lo->cost.steps, lo->cost.per_step(), lo->cost.solves / double(lo->cost.steps), above);
    lo->cost.print_profile("RK2");
    for (const Timed& t : timed) {
      std::printf("wall time to t = %g s: %s %.1f s%s, explicit RK2 %.1f s (measured: a full run at its largest "
                  "stable step)\n",
                  T, t.label.c_str(), t.to_end, scaled, lo->cost.seconds);
      // The largest stable step lies in [lo, hi): RK2's time to t_end between (T/hi) steps and the measured run.
      const double ratio = lo->cost.seconds / t.to_end;
      if (hi)
        std::printf("ratio explicit / implicit (%s): %.1f (paper: 43; with the largest stable step anywhere below "
                    "%.4g s: between %.1f and %.1f)\n",
                    t.label.c_str(), ratio, hi->dt, T / hi->dt * lo->cost.per_step() / t.to_end, ratio);
      else
        std::printf("ratio explicit / implicit (%s): at most %.1f (paper: 43)\n", t.label.c_str(), ratio);
      // The ratio is RK2's run over (steps x (evaluations x their cost + other work)): what fewer evaluations or no
      // other work would give, at this run's costs.
      const double rk2 = lo->cost.seconds, per_eval = t.steps_to_end * t.evaluation;
      std::printf("what sets it (%s): a step is %.2f residual evaluations of %.1f ms (forces, spreading, fluid, "
                  "interpolation) + %.1f ms of other work; an RK2 step costs %.1f ms (%.2f evaluations); with no "
                  "other work the ratio would be %.1f, with three evaluations and none %.1f; 43 needs at most %.2f "
                  "evaluations per step and no other work\n",
                  t.label.c_str(), t.solves, 1e3 * t.evaluation, 1e3 * t.other, 1e3 * lo->cost.per_step(),
                  lo->cost.per_step() / t.evaluation, rk2 / (per_eval * t.solves), rk2 / (3 * per_eval),
                  rk2 / (43 * per_eval));
    }
  } else if (hi) {
    const double steps = T / hi->dt, t_bound = steps * hi->cost.per_step();
    std::printf("RK2: no step reached t_end within the %.0f s budget (--rk2-budget); every step tried down to %.4g s "
                "blows up (there at t = %.4g s): the largest stable dt is below it (paper: 1.875e-6)\n",
                rk2_budget, hi->dt, hi->reached);
    hi->cost.print_profile("RK2");
    for (const Timed& t : timed) {
      std::printf("wall time to t = %g s: %s %.1f s%s, explicit RK2 more than %.1f s (more than %.0f steps at %.3f "
                  "s/step)\n",
                  T, t.label.c_str(), t.to_end, scaled, t_bound, steps, hi->cost.per_step());
      std::printf("ratio explicit / implicit (%s): at least %.1f (paper: 43)\n", t.label.c_str(), t_bound / t.to_end);
    }
  } else {
    std::printf("RK2: no probe decided within the %.0f s budget (--rk2-budget)\n", rk2_budget);
  }
  std::printf("peak resident memory: %.0f MiB\n", peak_rss_mib());
  return 0;
}
