#include "immerse/fluid/PoiseuilleFlow.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"

namespace immerse {

void set_poiseuille_flow(const Grid& grid, const FluidParams& params, FaceField& u) {
  bool walls = false;
  for (int d = 0; d < 3; ++d) {
    if (grid.periodic(d)) continue;
    walls = true;
    require(params.body_force[d] == 0.0, "fluid.body_force",
            std::string("zero along the wall axis ") + axis_name(d) + " for fluid.initial = \"poiseuille\"");
    require(norm(params.wall_lower[d]) == 0.0 && norm(params.wall_upper[d]) == 0.0,
            std::string("boundary.") + axis_name(d) + "_lower_velocity and _upper_velocity",
            "zero (resting walls) for fluid.initial = \"poiseuille\"");
  }
  require(walls, "fluid.initial", "\"rest\" when no axis has walls (\"poiseuille\" needs walls)");
  for (int d = 0; d < 3; ++d) {
    auto& v = u[d].values();
    std::fill(v.begin(), v.end(), -params.body_force[d]);
    if (params.body_force[d] != 0.0) FftHelmholtzSolver(grid, velocity_layout(d), FftPlanning::Estimate).solve(u[d], 0.0, params.mu);
  }
}

double poiseuille_mean_velocity(const Grid& grid, const FluidParams& params, int axis) {
  std::array<int, 3> n{};
  std::array<double, 3> length{};
  for (int d = 0; d < 3; ++d) {
    n[d] = grid.periodic(d) ? 2 : grid.n(d);
    length[d] = n[d] * grid.h();
  }
  const Grid section(n, length, {grid.bc(0), grid.bc(1), grid.bc(2)}, grid.origin());
  FaceField u(section);
  set_poiseuille_flow(section, params, u);
  double sum = 0;
  for (const double v : u[axis].values()) sum += v;
  return sum / static_cast<double>(u[axis].values().size());
}

}  // namespace immerse
