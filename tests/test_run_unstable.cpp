// An explicit membrane update past its stability limit (forward Euler, eq. 28, at a large step on the oscillating
// membrane): `immerse run` stops with status 3 and one message naming the step, the time, the membrane and the
// quantity that ran away, keeps the diagnostics and the last checkpoint written at a good step, saves the state it
// stopped in to unstable_state.h5, and ends with one line naming the checkpoint kept and the command that continues
// from it with half the step. An element that inverts is named with its area ratio and its distance to the walls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

// GCC 12's libstdc++ <regex> trips -Wmaybe-uninitialized inside its own automaton code at -O1 (a known false
// positive, GCC bug 105562); the warning is about the library header, not this test.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <regex>
#pragma GCC diagnostic pop

#include "PetscEnvironment.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

/// The small oscillating membrane with the contour forces of eq. (42) and forward Euler past their explicit limit
/// (dt = 0.35 s): it runs away at step 9 (with -dE/dX on this mesh it is stable at this step, and folds an element at
/// a larger one). A checkpoint every `checkpoint_every` steps; `end` the run's end time.
std::vector<std::string> runaway_sets(int checkpoint_every, double end = 35.0) {
  auto sets = small_membrane_sets(100);
  for (auto& s : sets)
    if (s.starts_with("time.end=")) s = "time.end=" + std::to_string(end);
    else if (s.starts_with("output.checkpoint_every=")) s = "output.checkpoint_every=" + std::to_string(checkpoint_every);
  sets.insert(sets.end(), {"time.scheme=\"euler\"", "time.dt=0.35", "time.max_speed=1.0", "membrane[0].force=\"contour\""});
  return sets;
}

/// The lines of `text`.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The command at the end of the last line of an unstable run ("...; continue with half the step: COMMAND"), split
/// into its words.
std::vector<std::string> suggested_command(const std::string& last_line) {
  const std::string marker = " with half the step: ";
  const auto at = last_line.find(marker);
  if (at == std::string::npos) return {};
  return shell_words(last_line.substr(at + marker.size()));
}

}  // namespace

TEST(RunUnstable, ExplicitSchemePastItsLimitStopsWithStatus3) {
  ScratchDir dir("unstable");
  const fs::path out = dir / "out";
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, runaway_sets(0)),
                             dir / "run");
  ASSERT_EQ(r.status, 3) << r.out << r.err;

  // immerse: run stopped: unstable at step 9, t = 3.15: membrane[0] node 8 speed exceeds time.max_speed (runaway) ...
  const auto lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 2u) << r.err;
  const std::regex line(R"(immerse: run stopped: unstable at step (\d+), t = ([0-9.e+-]+): membrane\[0\] node \d+ )"
                        R"((position is not finite|velocity is not finite|speed exceeds time\.max_speed \(runaway\)))"
                        R"( \(\|u\| = [^ ]+ m/s, bound 1\))");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(lines[0], m, line)) << r.err;
  const long step = std::stol(m[1]);
  EXPECT_GT(step, 1) << "forward Euler is stable for the first steps";
  EXPECT_NEAR(std::stod(m[2]), 0.35 * double(step), 1e-9);

  // The diagnostics hold every step before the unstable one, once each. No checkpoint was due: none is kept, the
  // unstable state is saved beside, and the last line says how to start again with half the step.
  const auto rows = read_csv(out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), std::size_t(step + 1));  // header, steps 0..step-1
  for (long s = 0; s < step; ++s) EXPECT_EQ(std::stol(rows[s + 1][0]), s);
  EXPECT_FALSE(fs::exists(out / "checkpoint.h5"));
  EXPECT_EQ(io::Checkpoint::read(out / "unstable_state.h5").get_int("step"), step);
  const std::string head = "immerse: no checkpoint kept: none was written before step " + std::to_string(step) +
                           " (output.checkpoint_every = 0); the state of step " + std::to_string(step) + " is in " +
                           (out / "unstable_state.h5").string() + "; start again with half the step: ";
  EXPECT_EQ(lines[1].rfind(head, 0), 0u) << lines[1];
  const auto words = suggested_command(lines[1]);
  ASSERT_GE(words.size(), 4u) << lines[1];
  EXPECT_EQ(words[0], immerse_program().string());
  EXPECT_EQ(std::count(words.begin(), words.end(), "--overwrite"), 1) << lines[1];
  EXPECT_EQ(std::count(words.begin(), words.end(), "--restart"), 0) << lines[1];
  EXPECT_EQ(words.back(), "time.dt=0.175");
}

// A checkpoint every 2 steps: the run becomes unstable at step 9 and checkpoint.h5 keeps step 8, not the unstable
// state. The command of the last line, run as printed, continues from it with half the step past the step that
// failed, to the end.
TEST(RunUnstable, UnstableRunKeepsTheLastGoodCheckpointAndContinuesWithHalfTheStep) {
  ScratchDir dir("unstable");
  const fs::path out = dir / "out";
  const double end = 7.0;
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, runaway_sets(2, end)),
                             dir / "run");
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  const auto lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 2u) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(lines[0], m, std::regex(R"(^immerse: run stopped: unstable at step (\d+), t = )")))
      << lines[0];
  const long step = std::stol(m[1]);
  ASSERT_GE(step, 3) << "the run must become unstable after its first checkpoint";
  const long kept = 2 * ((step - 1) / 2);

  const io::Checkpoint ck = io::Checkpoint::read(out / "checkpoint.h5");
  EXPECT_EQ(ck.get_int("step"), kept);
  EXPECT_NEAR(ck.get_double("fluid.time"), 0.35 * double(kept), 1e-12);
  EXPECT_EQ(io::Checkpoint::read(out / "unstable_state.h5").get_int("step"), step);
  std::ostringstream head;
  head.precision(10);
  head << "immerse: kept the last good checkpoint " << (out / "checkpoint.h5").string() << " (step " << kept
       << ", t = " << ck.get_double("fluid.time") << "); the state of step " << step << " is in "
       << (out / "unstable_state.h5").string() << "; continue with half the step: ";
  EXPECT_EQ(lines[1].rfind(head.str(), 0), 0u) << lines[1];

  const auto words = suggested_command(lines[1]);
  ASSERT_GE(words.size(), 4u) << lines[1];
  EXPECT_EQ(words[0], immerse_program().string());
  EXPECT_EQ(words.back(), "time.dt=0.175");
  const auto restart = std::find(words.begin(), words.end(), "--restart");
  ASSERT_NE(restart, words.end()) << lines[1];
  EXPECT_EQ(*(restart + 1), (out / "checkpoint.h5").string());
  const auto again = run_immerse({words.begin() + 1, words.end()}, dir / "again");
  ASSERT_EQ(again.status, 0) << again.out << again.err;
  EXPECT_EQ(again.err, "");
  // Steps kept..step at the first step, then (end - t_kept) / (dt / 2) steps of half the step.
  const long steps = kept + std::lround((end - 0.35 * double(kept)) / 0.175);
  const io::Checkpoint last = io::Checkpoint::read(out / "checkpoint.h5");
  EXPECT_EQ(last.get_int("step"), steps);
  EXPECT_NEAR(last.get_double("fluid.time"), end, 1e-9);
  EXPECT_EQ(last.get_double("stepper.dt"), 0.175);
  // The post-mortem file of the attempt that failed went with the continuation's first checkpoint.
  EXPECT_FALSE(fs::exists(out / "unstable_state.h5"));
  const auto rows = read_csv(out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), std::size_t(steps + 2));  // header, steps 0..steps
  EXPECT_NEAR(std::stod(rows[std::size_t(kept) + 2][2]), 0.175, 1e-12) << "the dt column after the restart";
}

// Forward Euler with -dE/dX at dt = 1 s folds an element of the membrane at its second step: the message names the
// membrane and the element, with the element's area against its stress-free area, the least of the membrane and the
// distance from the element to the nearest wall, each checked against the state it stopped in.
TEST(RunUnstable, InvertedElementIsNamedWithItsAreaRatioAndItsDistanceToTheWall) {
  ScratchDir dir("unstable");
  const fs::path out = dir / "out";
  auto sets = small_membrane_sets(50, 1.0);
  sets.insert(sets.end(), {"time.scheme=\"euler\"", "time.max_speed=100.0"});
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets), dir / "run");
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  const auto lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 2u) << r.err;
  // immerse: run stopped: step 2, t = 1: membrane[0] element 1: Jacobian <= 0 or not finite (element inverted or
  // degenerate); area ratio 1.36 (least of the membrane 0.619, element 10), 0.239 m from the wall y = 1
  const std::regex line(R"(immerse: run stopped: step (\d+), t = [0-9.e+-]+: membrane\[0\] element (\d+): Jacobian <= 0 )"
                        R"(or not finite \(element inverted or degenerate\); area ratio ([0-9.e+-]+) \(least of the )"
                        R"(membrane ([0-9.e+-]+), element (\d+)\), ([0-9.e+-]+) m from the wall ([xyz]) = ([01]))");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(lines[0], m, line)) << lines[0];
  const std::size_t element = std::stoul(m[2]);

  // The forces that failed are those at the trial positions of forward Euler (eq. 28) from the state it stopped in,
  // saved as the unstable state: X = X^n + dt U^n, with U^n as the run interpolated it (a restart is bitwise).
  const io::Checkpoint state = io::Checkpoint::read(out / "unstable_state.h5");
  EXPECT_EQ(state.get_int("step") + 1, std::stol(m[1]));
  Simulation sim(apply_scenario(run_schema().parse_string(state.get_string("config"), "unstable_state.h5")));
  sim.restore(state);
  const auto Xn = sim.op().membrane_positions(0), Un = sim.op().membrane_velocities(0);
  std::vector<Vec3> X(Xn.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    for (int a = 0; a < 3; ++a) X[i][a] = Xn[i][a] + 1.0 * Un[i][a];
  const Mesh& mesh = sim.mesh(0);
  const auto areas = element_areas(mesh, X), reference = element_areas(mesh, sim.reference(0));
  ASSERT_LT(element, areas.size());
  EXPECT_NEAR(std::stod(m[3]), areas[element] / reference[element], 5e-3 * areas[element] / reference[element]);
  const LeastAreaRatio least = least_area_ratio(mesh, X, reference);
  EXPECT_NEAR(std::stod(m[4]), least.ratio, 5e-3 * least.ratio);
  EXPECT_EQ(std::stoul(m[5]), least.element);
  // The unit box has walls on every side: the element's nearest approach to one of them, on the named one.
  double wall = 1e300;
  for (const int n : mesh.elements[element])
    for (int a = 0; a < 3; ++a) wall = std::min({wall, X[n][a], 1 - X[n][a]});
  EXPECT_NEAR(std::stod(m[6]), wall, 5e-3 * wall);
  const int axis = m[7].str()[0] - 'x';
  const double at = std::stod(m[8]);
  double closest = 1e300;
  for (const int n : mesh.elements[element]) closest = std::min(closest, std::abs(X[n][axis] - at));
  EXPECT_NEAR(closest, wall, 1e-12);
}

// An implicit step that inverts an element while it iterates is rejected and halved; the rejection line names the
// element with its area ratio and its distance to the wall, as the message that stops a run does.
TEST(RunUnstable, RejectedStepNamesTheInvertedElementWithItsAreaRatioAndItsDistanceToTheWall) {
  ScratchDir dir("unstable");
  auto sets = small_membrane_sets(3, 4.0);
  sets.push_back("time.max_speed=100.0");
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "out", sets), dir / "run");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // step 5, t = 8: step rejected with dt = 4 (membrane[0] element 0: Jacobian <= 0 or not finite (element inverted or
  // degenerate); area ratio 1.54 (least of the membrane 0.969, element 2), 0.185 m from the wall x = 0); retrying
  // with dt = 2
  const std::regex line(R"(step \d+, t = [0-9.e+-]+: step rejected with dt = 4 \(membrane\[0\] element \d+: Jacobian <= 0 )"
                        R"(or not finite \(element inverted or degenerate\); area ratio [0-9.e+-]+ \(least of the membrane )"
                        R"([0-9.e+-]+, element \d+\), [0-9.e+-]+ m from the wall [xyz] = [01]\); retrying with dt = 2)");
  const auto lines = lines_of(r.out);
  EXPECT_EQ(std::count_if(lines.begin(), lines.end(), [&](const std::string& l) { return std::regex_match(l, line); }),
            1)
      << r.out;
}

namespace {

/// The quick scenario without its membrane, on a 16^3 grid, with `sets` added: a box of fluid only.
RunResult run_fluid_only(const ScratchDir& dir, const std::vector<std::string>& sets) {
  const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
  std::ofstream(dir / "fluid_only.toml") << base.substr(0, base.find("[[membrane]]"));
  std::vector<std::string> all{"grid.nx=16", "grid.ny=16", "grid.nz=16", "time.dt=0.125", "time.end=1.0",
                               "output.fields_every=0"};
  all.insert(all.end(), sets.begin(), sets.end());
  return run_immerse(run_args(dir / "fluid_only.toml", dir / "out", all), dir / "run");
}

}  // namespace

// A fluid that overflows (a body force near the largest double) where no membrane samples it: status 3 at the
// first step, naming the fluid, the face and what is wrong; the unstable state is saved for inspection beside the
// checkpoint, which none was due to write.
TEST(RunUnstable, FluidThatTurnsNonFiniteStopsWithStatus3) {
  ScratchDir dir("unstable");
  const auto r = run_fluid_only(dir, {"fluid.body_force=[1e308,0,0]"});
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  const std::regex line(R"(immerse: run stopped: unstable at step 1, t = 0.125: fluid velocity u_x at face )"
                        R"(\(\d+, \d+, \d+\) is not finite\nimmerse: no checkpoint kept: [^\n]*\n)");
  EXPECT_TRUE(std::regex_match(r.err, line)) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "checkpoint.h5"));
  EXPECT_EQ(io::Checkpoint::read(dir / "out" / "unstable_state.h5").get_int("step"), 1);
}

// A fluid accelerated past time.max_speed (a body force along a periodic axis): status 3 with the speed found.
TEST(RunUnstable, FluidFasterThanTheSpeedBoundStopsWithStatus3) {
  ScratchDir dir("unstable");
  const auto r = run_fluid_only(dir, {"fluid.body_force=[1e4,0,0]", "boundary.x=\"periodic\""});
  ASSERT_EQ(r.status, 3) << r.out << r.err;
  const std::regex line(R"(immerse: run stopped: unstable at step 1, t = 0.125: fluid velocity u_x at face )"
                        R"(\(\d+, \d+, \d+\) exceeds time\.max_speed \(runaway\) \(\|u_x\| = [0-9.e+]+ m/s, bound 100\)\n)"
                        R"(immerse: no checkpoint kept: [^\n]*\n)");
  EXPECT_TRUE(std::regex_match(r.err, line)) << r.err;
}
