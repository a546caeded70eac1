// scenarios/rbc_shear_quick.toml (a biconcave Skalak red cell, Ca = 0.94, in simple shear between moving walls) to
// k t = 8 at lambda = 1 and lambda = 5, checked against the change of motion of Keller & Skalak, J. Fluid Mech. 120
// (1982): at lambda = 5 the cell flips like a rigid disc (its symmetry axis turns past a quarter turn and the
// membrane stays in place on the cell); at lambda = 1 the axis stays near the gradient direction while the membrane
// turns around the cell (tank-treading). The volume correction keeps the volume, the area constraint the area.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "immerse/membrane/Geometry.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "PetscEnvironment.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

struct Motion {
  double phi_min = 0, phi_max = 0, phi_end = 0;  ///< symmetry axis from z towards x (rad), continuous in time
  double rel_min = 0, rel_max = 0, rel_end = 0;  ///< a rim node's angle around the centroid minus phi (rad)
  double volume_change = 0, area_change = 0;     ///< largest |V/V0 - 1|, |A/A0 - 1|
};

// Angle in the x-z plane from +z towards +x, continued from `previous` (within pi of it).
double continued(double angle, double previous) {
  while (angle - previous > M_PI) angle -= 2 * M_PI;
  while (angle - previous < -M_PI) angle += 2 * M_PI;
  return angle;
}

Motion run_to(double kt_end, double lambda) {
  const double k = 1000.0;  // shear rate of the scenario (1/s)
  const std::vector<std::string> sets{"output.fields_every=0", "time.end=" + std::to_string(kt_end / k),
                                      "membrane[0].viscosity_ratio=" + std::to_string(lambda)};
  Simulation sim(apply_scenario(run_schema().parse_file(scenario_file("rbc_shear_quick.toml"), sets)));
  const Mesh& mesh = sim.mesh(0);
  const std::vector<Vec3> X0 = sim.op().membrane_positions(0);
  const MembraneGeometry g0 = measure(mesh, X0);
  // The node farthest out on the +x side of the rim, near the plane y = 0.
  std::size_t rim = 0;
  double best = -1e300;
  for (std::size_t i = 0; i < X0.size(); ++i) {
    const Vec3 r = X0[i] - g0.centroid;
    if (const double s = r.x - std::abs(r.y) - std::abs(r.z); s > best) best = s, rim = i;
  }
  Vec3 n_prev{0, 0, 1};
  double phi = 0, psi = 0;
  {
    const Vec3 r = X0[rim] - g0.centroid;
    psi = std::atan2(r.x, r.z);
  }
  Motion m;
  m.rel_min = m.rel_max = m.rel_end = psi - phi;
  while (!sim.finished()) {
    sim.advance([](const std::string&) {});
    const auto X = sim.op().membrane_positions(0);
    const MembraneGeometry g = measure(mesh, X);
    Vec3 n = g.axes[2];  // shortest axis of the equivalent ellipsoid: the disc's axis of symmetry
    if (dot(n, n_prev) < 0) n = -n;  // a director: keep its sign continuous
    n_prev = n;
    phi = continued(std::atan2(n.x, n.z), phi);
    const Vec3 r = X[rim] - g.centroid;
    psi = continued(std::atan2(r.x, r.z), psi);
    m.phi_min = std::min(m.phi_min, phi), m.phi_max = std::max(m.phi_max, phi);
    m.rel_min = std::min(m.rel_min, psi - phi), m.rel_max = std::max(m.rel_max, psi - phi);
    m.volume_change = std::max(m.volume_change, std::abs(g.volume / g0.volume - 1));
    m.area_change = std::max(m.area_change, std::abs(g.area / g0.area - 1));
  }
  m.phi_end = phi;
  m.rel_end = psi - phi;
  EXPECT_NEAR(k * sim.time(), kt_end, 1e-9);
  std::printf("red cell in shear, lambda = %g, k t = %g: phi %.3f ... %.3f, end %.3f rad; rim node minus phi %.3f "
              "... %.3f, end %.3f rad; largest volume change %.2e, area change %.2e\n",
              lambda, k * sim.time(), m.phi_min, m.phi_max, m.phi_end, m.rel_min, m.rel_max, m.rel_end,
              m.volume_change, m.area_change);
  return m;
}

}  // namespace

TEST(RbcShear, TheCellTankTreadsAtViscosityRatioOneAndTumblesAtFive) {
  const double start = M_PI / 2;  // the rim node starts a quarter turn from the axis (along x, the axis along z)
  const Motion five = run_to(8.0, 5.0);
  EXPECT_GT(five.phi_end, 0.6 * M_PI);  // flipping: the axis has turned past the flow direction
  EXPECT_GT(five.phi_min, -0.05 * M_PI);  // and only in the sense of the flow's rotation
  EXPECT_LT(five.rel_max - start, 0.15 * M_PI);  // the membrane stays in place on the cell
  EXPECT_GT(five.rel_min - start, -0.15 * M_PI);
  EXPECT_LT(five.volume_change, 1e-8);
  EXPECT_LT(five.area_change, 0.02);

  const Motion one = run_to(8.0, 1.0);
  EXPECT_LT(one.phi_max, 0.05 * M_PI);  // no flip: the axis stays within a quarter turn of the gradient direction
  EXPECT_GT(one.phi_min, -0.45 * M_PI);
  EXPECT_GT(one.rel_end - start, 0.5 * M_PI);  // tank-treading: the rim node has moved around the cell
  EXPECT_LT(one.volume_change, 1e-8);
  EXPECT_LT(one.area_change, 0.02);
}
