#include "immerse/scenario/TubeFlowRun.hpp"

#include <numbers>

#include "immerse/core/Error.hpp"
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
          {"relative_viscosity", "1", "apparent viscosity over fluid.mu: poiseuille_flow_rate / flow_rate"}};
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
  const double G = dot(prm.body_force, s.axis);
  t.poiseuille = std::numbers::pi * G * std::pow(s.radius, 4) / (8 * prm.mu);
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
  row.push_back(q);
  row.push_back(t.poiseuille);
  row.push_back(t.poiseuille / q);
}

}  // namespace immerse
