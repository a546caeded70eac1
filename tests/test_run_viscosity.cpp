// A capsule with a viscosity contrast in simple shear (docs/viscosity-contrast.md): the quick capsule_shear run at
// G = 0.01 with λ = 1 and λ = 5, against the small-deformation theory of Barthès-Biesel & Rallison (1981, J. Fluid
// Mech. 113): at first order in G the steady Taylor deformation, D = (25/4) G, does not depend on the viscosity ratio
// and the inclination is π/4; the viscosity ratio enters at the next order, where the inclination decreases as λ
// grows.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

struct Steady {
  double D = 0, theta = 0;  // means over kt in [2, 3]
};

Steady run_capsule(const ScratchDir& dir, double lambda) {
  const fs::path out = dir / ("lambda" + std::to_string(static_cast<int>(lambda)));
  const auto r = run_immerse(run_args(scenario_file("capsule_shear_quick.toml"), out,
                                      {"scenario.G=0.01", "scenario.kt_end=3", "output.fields_every=0",
                                       "output.checkpoint_every=0", "membrane[0].viscosity_ratio=" + std::to_string(lambda)}),
                             out.string() + "_log", {"OMP_NUM_THREADS=2"});
  EXPECT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(out / "diagnostics.csv");
  std::size_t kt = 0, D = 0, theta = 0;
  for (std::size_t c = 0; c < rows.at(0).size(); ++c) {
    if (rows[0][c] == "kt") kt = c;
    if (rows[0][c] == "D_xz") D = c;
    if (rows[0][c] == "theta") theta = c;
  }
  Steady s;
  int n = 0;
  for (std::size_t i = 1; i < rows.size(); ++i)
    if (std::stod(rows[i][kt]) >= 2.0 - 1e-9) {
      s.D += std::stod(rows[i][D]);
      s.theta += std::stod(rows[i][theta]);
      ++n;
    }
  EXPECT_GT(n, 10);
  s.D /= n;
  s.theta /= n;
  return s;
}

}  // namespace

// Tolerances: at this quick size (32³ cells, h = a/6.4, 642 nodes) the same run at λ = 1 lies about 20 % above
// (25/4) G (the regularized delta function widens the capsule by about h/2, and the mesh starts at D = 0.002); the
// measured D at λ = 5 is within 10 % of the theory and of the λ = 1 run, whose difference is the O(G²) term plus the
// discretization's. The inclination drops by about 0.1 rad from λ = 1 to 5.
TEST(ViscosityContrastShear, SteadyDeformationIsTheSmallDeformationTheoryAndTheInclinationDecreasesWithLambda) {
  ScratchDir dir("viscosity_shear");
  const Steady one = run_capsule(dir, 1), five = run_capsule(dir, 5);
  const double theory = 25.0 / 4.0 * 0.01;
  RecordProperty("D_lambda1", std::to_string(one.D));
  RecordProperty("D_lambda5", std::to_string(five.D));
  RecordProperty("theta_lambda1", std::to_string(one.theta));
  RecordProperty("theta_lambda5", std::to_string(five.theta));
  std::printf("D: lambda 1 %.4f, lambda 5 %.4f, theory %.4f; theta: lambda 1 %.4f, lambda 5 %.4f\n", one.D, five.D,
              theory, one.theta, five.theta);
  EXPECT_NEAR(five.D, theory, 0.2 * theory);
  EXPECT_NEAR(five.D, one.D, 0.15 * one.D);
  EXPECT_LT(five.theta, one.theta - 0.05);
  EXPECT_LT(one.theta, std::numbers::pi / 4);
}
