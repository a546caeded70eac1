// scenario.kind = "suspension_shear" (src/immerse/scenario/SuspensionShearRun.hpp): the relative viscosity of plane
// Couette flow from the wall stress, exactly 1 without cells; red cells packed at a few per cent raise it and keep
// their volume; the kind's one-line refusals of walls that do not shear.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/scenario/SuspensionShearRun.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "PetscEnvironment.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

const char* kCellFree = R"(
[scenario]
kind = "suspension_shear"
[domain]
Lx = 8e-6
Ly = 6e-6
Lz = 1e-5
[grid]
nx = 8
ny = 6
nz = 10
[boundary]
x = "periodic"
y = "periodic"
z = "wall"
z_lower_velocity = [-5e-3, 0.0, 0.0]
z_upper_velocity = [5e-3, 0.0, 0.0]
[fluid]
rho = 1000.0
mu = 1.2e-3
[time]
dt = 1e-4
end = 3e-4
)";

io::Config resolve(const std::string& text, const std::vector<std::string>& sets = {}) {
  return apply_scenario(run_schema().parse_string(text, "test", sets));
}

std::string error_of(const std::string& text, const std::vector<std::string>& sets) {
  try {
    resolve(text, sets);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The scenario's run columns after the last step: volume fraction, both wall stresses, relative viscosity.
std::vector<double> run_values(const Simulation& sim, const SuspensionShearRun& run) {
  std::vector<double> row;
  run.add_run_values(sim, row);
  return row;
}

}  // namespace

// Without cells the fluid started at rest becomes the plane Couette flow, whose wall stress is mu k on both walls.
TEST(SuspensionShear, WithoutCellsTheRelativeViscosityIsOneOnceTheFlowIsCouette) {
  const io::Config config = resolve(kCellFree, {"fluid.initial=\"couette\""});
  Simulation sim(config);
  SuspensionShearRun run(config);
  while (!sim.finished()) sim.advance([](const std::string&) {});
  const auto v = run_values(sim, run);
  ASSERT_EQ(v.size(), run.run_columns().size());
  const double k = 1e-2 / 1e-5;
  EXPECT_EQ(v[0], 0.0);
  EXPECT_NEAR(v[1], 1.2e-3 * k, 1e-12 * 1.2e-3 * k);
  EXPECT_NEAR(v[2], 1.2e-3 * k, 1e-12 * 1.2e-3 * k);
  EXPECT_NEAR(v[3], 1.0, 1e-12);
}

// Five red cells of the quick scenario (H = 3.4 %; 2,562 nodes each, enough for so short a run) over k t = 0.5: the
// wall stress rises above the cell-free value by more than the cells' volume fraction (Einstein's 2.5 H for rigid
// spheres; deformable cells add less, but at least H) and less than ten times it, and the normal-shift correction
// holds the volume fraction.
TEST(SuspensionShear, RedCellsRaiseTheWallStressAndKeepTheirVolume) {
  const io::Config config = resolve(read_text(scenario_file("suspension_shear_quick.toml")),
                                    {"packing.volume_fraction=0", "packing.count=5", "time.end=5e-4",
                                     "output.fields_every=0", "membrane[0].mesh.level=3"});
  Simulation sim(config);
  SuspensionShearRun run(config);
  const double H0 = run_values(sim, run)[0];
  const MembraneGeometry cell = measure(sim.mesh(0), sim.op().membrane_positions(0));
  EXPECT_NEAR(H0, 5 * cell.volume / (2.4e-5 * 2.4e-5 * 2.4e-5), 1e-12);
  while (!sim.finished()) sim.advance([](const std::string&) {});
  const auto v = run_values(sim, run);
  std::printf("5 red cells, H = %.4f: relative viscosity %.4f at k t = 0.5 (walls %.4g and %.4g Pa)\n", v[0], v[3],
              v[1], v[2]);
  EXPECT_NEAR(v[0], H0, 1e-10);
  EXPECT_GT(v[3] - 1, H0);
  EXPECT_LT(v[3] - 1, 10 * H0);
  EXPECT_NEAR(v[3], 0.5 * (v[1] + v[2]) / (1.2e-3 * 1000.0), 1e-12);
}

TEST(SuspensionShear, WallsThatDoNotShearAreRefusedNamingTheKey) {
  EXPECT_EQ(error_of(kCellFree, {"boundary.z_upper_velocity=[-5e-3, 0.0, 0.0]"}).rfind(
                "boundary.z_upper_velocity = [-0.005, 0.0, 0.0]: scenario.kind = \"suspension_shear\" needs", 0),
            0u)
      << error_of(kCellFree, {"boundary.z_upper_velocity=[-5e-3, 0.0, 0.0]"});
  EXPECT_EQ(error_of(kCellFree, {"boundary.x=\"wall\""}).rfind("boundary.x: must be \"periodic\"", 0), 0u)
      << error_of(kCellFree, {"boundary.x=\"wall\""});
  EXPECT_EQ(error_of(kCellFree, {"boundary.z=\"periodic\"", "boundary.z_lower_velocity=[0.0, 0.0, 0.0]",
                                 "boundary.z_upper_velocity=[0.0, 0.0, 0.0]"})
                .rfind("boundary.z: must be \"wall\"", 0),
            0u);
}
