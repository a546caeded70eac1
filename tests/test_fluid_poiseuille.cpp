// The discrete Poiseuille flow (PoiseuilleFlow.hpp): an exact steady state of the Navier-Stokes step, whose flow
// rate converges at second order to the series solution of the rectangular duct; and its input checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/PoiseuilleFlow.hpp"
#include "immerse/verify/Convergence.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

// Duct |x| < a = 1, |z| < b = 1/2, periodic along y (the flow), n cells across z.
Grid duct(int n) { return Grid({2 * n, 2, n}, {2.0, 2.0 / n, 1.0}, {W, P, W}, {-1.0, 0.0, -0.5}); }

FluidParams driven(double G) {
  FluidParams prm;
  prm.rho = 3;
  prm.mu = 0.7;
  prm.body_force = {0, G, 0};
  return prm;
}

TEST(PoiseuilleFlow, IsASteadyStateOfTheDiscreteStep) {
  const Grid g = duct(8);
  const FluidParams prm = driven(2.5);
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  set_poiseuille_flow(g, prm, a.u);
  const FaceField u0 = a.u;
  for (int n = 0; n < 4; ++n) {
    ns.step(a, FaceField(g), 0.05, b);
    std::swap(a, b);
  }
  const auto& v = u0[1].values();
  const double umax = *std::max_element(v.begin(), v.end());
  EXPECT_GT(umax, 0.1);
  double change = 0;
  for (int d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a.u[d].values().size(); ++i)
      change = std::max(change, std::abs(a.u[d].values()[i] - u0[d].values()[i]));
  EXPECT_LE(change / umax, 1e-13);
}

TEST(PoiseuilleFlow, MeanVelocityConvergesAtSecondOrderToTheSeries) {
  const FluidParams prm = driven(2.5);
  const DuctPoiseuille series{1.0, 0.5, prm.body_force.y, prm.mu};
  const double exact = series.flow_rate() / (4 * series.a * series.b);
  std::vector<double> errors;
  for (int n : {8, 16, 32}) {
    const Grid g = duct(n);
    FaceField u(g);
    set_poiseuille_flow(g, prm, u);
    double sum = 0;
    for (double v : u[1].values()) sum += v;
    errors.push_back(std::abs(sum / double(u[1].values().size()) - exact) / exact);
  }
  EXPECT_LE(errors.back(), 3e-3);
  EXPECT_GE(verify::min_observed_order(errors), 1.9) << errors[0] << " " << errors[1] << " " << errors[2];
}

// The mean velocity along the flow, taken on a section two cells long, is that of the whole duct, 40 cells long.
TEST(PoiseuilleFlow, MeanVelocityOfTheSectionIsThatOfTheDuct) {
  const FluidParams prm = driven(2.5);
  const Grid g({16, 40, 8}, {2.0, 5.0, 1.0}, {W, P, W}, {-1.0, 0.0, -0.5});
  FaceField u(g);
  set_poiseuille_flow(g, prm, u);
  double sum = 0;
  for (double v : u[1].values()) sum += v;
  const double whole = sum / double(u[1].values().size());
  EXPECT_GT(whole, 0.01);
  EXPECT_NEAR(poiseuille_mean_velocity(g, prm, 1), whole, 1e-13 * whole);
  EXPECT_EQ(poiseuille_mean_velocity(g, prm, 0), 0.0);
}

TEST(PoiseuilleFlow, RejectsMovingWallsForcesAcrossWallsAndBoxesWithoutWalls) {
  const Grid g = duct(4);
  FaceField u(g);
  FluidParams moving = driven(1.0);
  moving.wall_upper[2] = {0.1, 0, 0};
  EXPECT_THROW(set_poiseuille_flow(g, moving, u), InputError);
  FluidParams across = driven(1.0);
  across.body_force.z = 1.0;
  EXPECT_THROW(set_poiseuille_flow(g, across, u), InputError);
  const Grid periodic({4, 4, 4}, {1.0, 1.0, 1.0}, {P, P, P});
  FaceField up(periodic);
  EXPECT_THROW(set_poiseuille_flow(periodic, driven(1.0), up), InputError);
}

}  // namespace
