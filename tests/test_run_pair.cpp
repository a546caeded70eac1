// scenarios/capsule_pair_quick.toml (two neo-Hookean capsules, G = 0.05, 642 nodes each, crossing in simple shear
// from dx/a = -4, dz/a = 0.75; Lac, Morel & Barthes-Biesel, J. Fluid Mech. 573, 149-169 (2007)) in a box half as
// deep along y (4a instead of 8a: a 48 x 12 x 24 grid, 180 steps to k t = 9), checked against the physics of the
// crossing: the upper capsule passes the lower one (dx changes sign), the gradient-direction separation dz rises
// while the two overlap along x and ends above its initial value (the irreversible drift), the motion is the same
// for both capsules (equal and opposite centroid displacements, equal volumes, by the symmetry of the pair about the
// box centre), and no node of one capsule ever lies inside the other (winding number, MembraneClearance.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "PetscEnvironment.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

// Nodes of membrane `m` that lie inside the other membrane (only nodes closer than the radius `a` to the other's
// centroid can be inside it: the capsules stay close to spheres of radius a at G = 0.05).
int nodes_inside_the_other(const Simulation& sim, const std::vector<std::vector<Vec3>>& X, std::size_t m, double a) {
  const std::size_t o = 1 - m;
  const Vec3 c = measure(sim.mesh(o), X[o]).centroid;
  int inside = 0;
  for (const auto& p : X[m])
    if (norm(p - c) < 1.5 * a && encloses(sim.mesh(o), X[o], p)) ++inside;
  return inside;
}

}  // namespace

TEST(CapsulePair, TheCapsulesCrossWithoutOverlapAndDriftApartInTheGradientDirection) {
  const double a = 5e-6;
  const std::vector<std::string> sets{"output.fields_every=0", "domain.Ly=2e-5", "grid.ny=12",
                                      "membrane[0].center=[5e-5, 1e-5, 1.8125e-5]",
                                      "membrane[1].center=[3e-5, 1e-5, 2.1875e-5]"};
  Simulation sim(apply_scenario(run_schema().parse_file(scenario_file("capsule_pair_quick.toml"), sets)));
  auto positions = [&] {
    return std::vector<std::vector<Vec3>>{sim.op().membrane_positions(0), sim.op().membrane_positions(1)};
  };
  auto offset = [&](const std::vector<std::vector<Vec3>>& X) {  // upper (membrane[1]) from lower (membrane[0])
    return (measure(sim.mesh(1), X[1]).centroid - measure(sim.mesh(0), X[0]).centroid) / a;
  };
  const auto X0 = positions();
  const Vec3 start = offset(X0);
  const Vec3 c0 = measure(sim.mesh(0), X0[0]).centroid, c1 = measure(sim.mesh(1), X0[1]).centroid;
  EXPECT_NEAR(start.x, -4.0, 1e-6);
  EXPECT_NEAR(start.z, 0.75, 1e-6);

  double largest_dz = start.z, dz_at_crossing = 0, min_gap = 1e300;
  bool crossed = false;
  int inside = 0, checks = 0;
  Vec3 previous = start;
  while (!sim.finished()) {
    sim.advance([](const std::string&) {});
    const auto X = positions();
    const Vec3 d = offset(X);
    largest_dz = std::max(largest_dz, d.z);
    if (previous.x < 0 && d.x >= 0) {
      crossed = true;
      dz_at_crossing = d.z;
    }
    previous = d;
    if (const auto gap = closest_foreign_nodes(sim.grid(), X, 2 * a)) min_gap = std::min(min_gap, gap->distance);
    if (sim.step() % 4 == 0 || std::abs(d.x) < 1.5) {  // every step while they overlap along x
      ++checks;
      inside += nodes_inside_the_other(sim, X, 0, a) + nodes_inside_the_other(sim, X, 1, a);
    }
  }
  const auto X = positions();
  const Vec3 end = offset(X);
  std::printf("capsule pair: k t = %.3g, dz/a %.4f -> largest %.4f (%.4f at dx = 0) -> final %.4f, dx/a %.4f -> "
              "%.4f, closest nodes %.3g a, %d winding checks\n",
              40 * sim.time(), start.z, largest_dz, dz_at_crossing, end.z, start.x, end.x, min_gap / a, checks);

  EXPECT_NEAR(40 * sim.time(), 9.0, 1e-9);
  EXPECT_TRUE(crossed) << "dx/a never changed sign";
  EXPECT_GT(end.x, 2.5);                      // passed and separated along the flow (about 3.5)
  EXPECT_GT(dz_at_crossing, start.z + 0.5);   // the upper capsule rides over the lower one
  EXPECT_GT(largest_dz, end.z + 0.2);         // and comes down after
  EXPECT_GT(end.z, start.z + 0.3);            // the drift: 0.75 -> about 1.37 at this size
  EXPECT_LT(std::abs(end.y), 1e-6);           // no motion out of the shear plane
  EXPECT_EQ(inside, 0) << "node-steps with a node of one capsule inside the other";
  EXPECT_GT(checks, 40);
  EXPECT_GT(min_gap, 0.0);

  // The pair is symmetric under the half-turn about the y axis through the box centre: the centroids move by
  // equal and opposite amounts, the two deform alike.
  const Vec3 e0 = measure(sim.mesh(0), X[0]).centroid - c0, e1 = measure(sim.mesh(1), X[1]).centroid - c1;
  EXPECT_LT(norm(e0 + e1), 1e-3 * a) << "centroid displacements not opposite";
  const MembraneGeometry g0 = measure(sim.mesh(0), X[0]), g1 = measure(sim.mesh(1), X[1]);
  EXPECT_NEAR(g0.volume, g1.volume, 1e-6 * g1.volume);
  EXPECT_LT(std::abs(g0.volume / (4 * M_PI * a * a * a / 3) - 1), 0.02);
}
