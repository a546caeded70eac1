#include "immerse/scenario/CapsuleConstrictionRun.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/simulation/SimulationInterface.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

std::vector<Column> CapsuleConstrictionRun::membrane_columns() const {
  return {{"length_x", "m", "extent along x: the largest minus the least node x (Park & Dimitrakopoulos' l_x)"},
          {"length_y", "m", "extent along y (l_y)"},
          {"length_z", "m", "extent along z (l_z)"},
          {"throat_position", "m",
           "the centroid's position along the constriction's axis from the throat's centre (nearest periodic image)"},
          {"in_throat", "1", "1 while the centroid is within the throat's length; else 0"}};
}

std::vector<Column> CapsuleConstrictionRun::run_columns() const {
  return {{"flow_rate", "m^3/s",
           "volume flow rate along the constriction's axis: the mean of u along it over the box's fluid points times "
           "the box's cross-section"},
          {"pressure_gradient", "Pa/m",
           "mean pressure gradient driving the flow: the body force along the axis (fluid.flow_rate's controller "
           "included)"}};
}

void CapsuleConstrictionRun::attach(SimulationInterface& sim) {
  const FluidParams& prm = sim.fluid_params();
  if (!prm.walls || prm.walls->shapes().empty() || prm.walls->shapes()[0].kind != WallShape::Kind::Constriction)
    throw InputError(
        "wall[0].shape: must be \"constriction\" for scenario.kind = \"capsule_constriction\" (the "
        "constriction it measures)");
  const WallShape& s = prm.walls->shapes()[0];
  axis_ = s.axis.x != 0 ? 0 : s.axis.y != 0 ? 1 : 2;
  if (prm.flow_axis != axis_)
    throw InputError(std::string("fluid.flow_rate: must be along ") + axis_name(axis_) +
                     ", the constriction's axis, for scenario.kind = \"capsule_constriction\"");
  const Grid& g = sim.grid();
  centre_ = s.center[axis_];
  half_length_ = 0.5 * s.throat[axis_];
  period_ = g.length(axis_);
  section_ = g.length((axis_ + 1) % 3) * g.length((axis_ + 2) % 3);
  const std::array<int, 3> n = g.face_shape(axis_);
  fluid_.resize(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  std::size_t f = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) fluid_[f++] = prm.walls->distance(g.face_position(axis_, i, j, k)) > 0;
}

void CapsuleConstrictionRun::add_membrane_values(const std::vector<Vec3>& X, std::vector<double>& row) const {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi = -lo, sum{};
  for (const Vec3& x : X) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], x[a]);
      hi[a] = std::max(hi[a], x[a]);
    }
    sum += x;
  }
  for (int a = 0; a < 3; ++a) row.push_back(hi[a] - lo[a]);
  double along = sum[axis_] / static_cast<double>(X.size()) - centre_;
  along -= period_ * std::floor(along / period_ + 0.5);
  row.push_back(along);
  row.push_back(std::abs(along) <= half_length_ ? 1.0 : 0.0);
}

void CapsuleConstrictionRun::add_run_values(const SimulationInterface& sim, std::vector<double>& row) const {
  const std::vector<double>& u = sim.committed_fluid().u[axis_].values();
  double s = 0;
  for (std::size_t f = 0; f < u.size(); ++f)
    if (fluid_[f]) s += u[f];
  row.push_back(s / static_cast<double>(u.size()) * section_);
  row.push_back(sim.step_body_force()[axis_]);
}

}  // namespace immerse
