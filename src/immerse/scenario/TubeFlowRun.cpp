#include "immerse/scenario/TubeFlowRun.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/simulation/SimulationInterface.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

std::vector<Column> TubeFlowRun::run_columns() const {
  return {{"flow_rate", "m^3/s",
           "volume flow rate through the tube of wall[0]: the integral of u·t over "
           "the fluid over the length of the axis"},
          {"poiseuille_flow_rate", "m^3/s",
           "Poiseuille flow rate pi G R^4 / (8 mu) with G the body force along the "
           "tube axis"},
          {"relative_viscosity", "1", "apparent viscosity over fluid.mu: poiseuille_flow_rate / flow_rate"},
          {"tube_hematocrit", "1", "the membranes' volume over the tube's fluid volume (0 without cells)"},
          {"cell_free_layer", "m",
           "R minus the mean over slices of the tube (one grid spacing long) holding membrane nodes of the largest "
           "node distance from the axis in the slice (nan without cells)"}};
}

void TubeFlowRun::attach(SimulationInterface& sim) {
  const FluidParams& prm = sim.fluid_params();
  if (!prm.walls || prm.walls->shapes().empty() || prm.walls->shapes()[0].kind != WallShape::Kind::Tube)
    throw InputError(
        "wall[0].shape: must be \"tube\" for scenario.kind = "
        "\"tube_flow\" (the tube it measures)");
  const WallShape& s = prm.walls->shapes()[0];
  const Grid& g = sim.grid();
  Tube t;
  t.axis = s.axis;
  t.period = s.period;
  t.centre = s.center;
  t.radius = s.radius;
  t.fluid_volume = prm.walls->fluid_volume(g);
  t.poiseuille = std::numbers::pi * std::pow(s.radius, 4) / (8 * prm.mu);  // per unit body force
  for (int d = 0; d < 3; ++d) {
    const std::array<int, 3> n = g.face_shape(d);
    t.fluid[d].resize(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    std::size_t f = 0;
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) t.fluid[d][f++] = prm.walls->distance(g.face_position(d, i, j, k)) > 0;
  }
  tube_ = std::move(t);
}

void TubeFlowRun::add_run_values(const SimulationInterface& sim, std::vector<double>& row) const {
  const Tube& t = *tube_;
  const FluidState& fluid = sim.committed_fluid();
  double sum = 0;
  for (int d = 0; d < 3; ++d) {
    if (t.axis[d] == 0) continue;
    const std::vector<double>& u = fluid.u[d].values();
    double s = 0;
    for (std::size_t f = 0; f < u.size(); ++f)
      if (t.fluid[d][f]) s += u[f];
    sum += t.axis[d] * s;
  }
  const double h = sim.grid().h();
  const double q = sum * h * h * h / t.period;
  const double poiseuille = t.poiseuille * dot(sim.step_body_force(), t.axis);  // with what fluid.flow_rate added
  row.push_back(q);
  row.push_back(poiseuille);
  row.push_back(poiseuille / q);
  // The cells: their volume, and per slice along the axis the outermost node.
  const std::vector<std::vector<Vec3>> X = sim.positions();
  double cells = 0;
  const auto bins = static_cast<std::size_t>(std::max(1.0, std::round(t.period / h)));
  std::vector<double> outer(bins, -1.0);
  for (std::size_t m = 0; m < X.size(); ++m) {
    cells += volume(sim.mesh(m), X[m]);
    for (const Vec3& x : X[m]) {
      Vec3 r = x - t.centre;
      const double along = dot(r, t.axis);
      const double radial = norm(r - along * t.axis);
      const double w = along / t.period - std::floor(along / t.period);
      const std::size_t b = std::min(bins - 1, static_cast<std::size_t>(w * static_cast<double>(bins)));
      outer[b] = std::max(outer[b], radial);
    }
  }
  double edge = 0;
  int filled = 0;
  for (const double o : outer)
    if (o >= 0) edge += o, ++filled;
  row.push_back(cells / t.fluid_volume);
  row.push_back(filled > 0 ? t.radius - edge / filled : std::numeric_limits<double>::quiet_NaN());
}

}  // namespace immerse
