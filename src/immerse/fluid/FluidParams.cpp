#include "immerse/fluid/FluidParams.hpp"

#include <cmath>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

void FluidParams::validate(const Grid& grid) const {
  require(std::isfinite(rho) && rho > 0, "fluid.rho", rho, "> 0");
  require(std::isfinite(mu) && mu > 0, "fluid.mu", mu, "> 0");
  require(std::isfinite(implicit_ratio) && implicit_ratio >= 1, "implicit viscosity ratio", implicit_ratio, ">= 1");
  for (int d = 0; d < 3; ++d)
    require(std::isfinite(body_force[d]), std::string("fluid.body_force.") + axis_name(d), body_force[d], "finite");
  if (flow_axis >= 0)
    require(grid.periodic(flow_axis), std::string("fluid.flow_rate.") + axis_name(flow_axis),
            std::string("zero: a flow rate is held along a periodic axis, and ") + axis_name(flow_axis) + " has walls");
  for (int a = 0; a < 3; ++a) {
    if (grid.periodic(a)) continue;
    for (int d = 0; d < 3; ++d) {
      const std::string lo = std::string("fluid.wall_velocity.") + axis_name(a) + "_lower." + axis_name(d);
      const std::string hi = std::string("fluid.wall_velocity.") + axis_name(a) + "_upper." + axis_name(d);
      require(std::isfinite(wall_lower[a][d]), lo, wall_lower[a][d], "finite");
      require(std::isfinite(wall_upper[a][d]), hi, wall_upper[a][d], "finite");
    }
    require(wall_lower[a][a] == wall_upper[a][a],
            std::string("fluid.wall_velocity.") + axis_name(a) + "_upper." + axis_name(a), wall_upper[a][a],
            "equal to the lower wall's normal velocity (zero net flux through the walls)");
  }
}

FluidParams step_params(const FluidParams& params, const FluidState& state) {
  FluidParams p = params;
  if (p.flow_axis >= 0) p.body_force[p.flow_axis] += state.flow_force;
  return p;
}

}  // namespace immerse
