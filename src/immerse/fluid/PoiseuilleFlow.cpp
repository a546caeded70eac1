#include "immerse/fluid/PoiseuilleFlow.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/GhostCellWalls.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

namespace {

// [[wall]] tubes along one grid axis a with the body force along it: the steady flow does not vary along a, so it is
// solved on a section two cells long (GhostCellWalls::steady_flow) and repeated along a.
void set_tube_poiseuille_flow(const Grid& grid, const FluidParams& params, FaceField& u) {
  int a = -1;
  for (int d = 0; d < 3; ++d)
    if (params.body_force[d] != 0) {
      require(a < 0, "fluid.body_force", "along one axis for fluid.initial = \"poiseuille\" with [[wall]] shapes");
      a = d;
    }
  for (int d = 0; d < 3; ++d) std::fill(u[d].values().begin(), u[d].values().end(), 0.0);
  if (a < 0) return;
  std::vector<WallShape> section_shapes = params.walls->shapes();
  std::array<int, 3> n = grid.n();
  std::array<double, 3> length{};
  n[a] = 2;
  for (int d = 0; d < 3; ++d) length[d] = n[d] * grid.h();
  if (!params.walls->invariant_along(a))
    throw InputError(std::string("fluid.initial = \"poiseuille\": the [[wall]] shapes must not vary along ") +
                     axis_name(a) + ", the body force (tubes along it, boxes spanning it)");
  for (WallShape& s : section_shapes) {
    s.center[a] = grid.origin()[a] + grid.h();
    s.size[a] = std::max(s.size[a], length[a]);  // a box spanning the box spans the section
  }
  const Grid section(n, length, {grid.bc(0), grid.bc(1), grid.bc(2)}, grid.origin());
  GhostCellWalls walls(section, WallGeometry(section_shapes, section));
  FftHelmholtzSolver fast(section, velocity_layout(a), FftPlanning::Estimate);
  Array3 s(n[0], n[1], n[2]);
  walls.steady_flow(a, params.body_force[a], params.mu, s, fast);
  Array3& ua = u[a];
  for (int k = 0; k < grid.n(2); ++k)
    for (int j = 0; j < grid.n(1); ++j)
      for (int i = 0; i < grid.n(0); ++i) {
        std::array<int, 3> q{i, j, k};
        q[a] = 0;
        ua(i, j, k) = s(q[0], q[1], q[2]);
      }
}

}  // namespace

void set_poiseuille_flow(const Grid& grid, const FluidParams& params, FaceField& u) {
  if (params.walls) {
    set_tube_poiseuille_flow(grid, params, u);
    return;
  }
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
