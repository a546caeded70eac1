#include "immerse/scenario/ChannelRun.hpp"

#include <limits>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/PoiseuilleFlow.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

std::vector<Column> ChannelRun::run_columns() const {
  return {{"mean_velocity", "m/s", "mean fluid velocity along the flow (y) over the box"},
          {"flow_rate", "m^3/s", "volume flow rate through a cross-section: mean_velocity times Lx Lz"},
          {"pressure_drop", "Pa", "the pressure drop over the period Ly that the body force stands for: f_y Ly"},
          {"relative_viscosity", "1",
           "apparent viscosity over the fluid's: U_0 / mean_velocity with U_0 the cell-free mean velocity under the "
           "same body force (nan when a wall moves or f_y = 0)"}};
}

const ChannelRun::Duct& ChannelRun::duct(const SimulationInterface& sim) const {
  if (duct_) return *duct_;
  const Grid& grid = sim.grid();
  FluidParams unit = run_fluid_params(sim.config());
  Duct d{grid.length(0) * grid.length(2), grid.length(1), std::numeric_limits<double>::quiet_NaN()};
  unit.body_force = {0, 1, 0};
  try {
    d.cell_free = poiseuille_mean_velocity(grid, unit, 1);
  } catch (const InputError&) {
    // A moving wall: no cell-free flow under the body force alone.
  }
  return duct_.emplace(d);
}

// The flow rate through a cross-section over its area: on the periodic y axis every y-face is distinct, and the
// faces tile the box.
void ChannelRun::add_run_values(const SimulationInterface& sim, std::vector<double>& row) const {
  const Duct& d = duct(sim);
  const double U = sim.mean_velocity(1);
  row.push_back(U);
  row.push_back(U * d.section);
  const double G = sim.step_body_force()[1];
  row.push_back(G * d.period);
  row.push_back(G != 0 ? d.cell_free * G / U : std::numeric_limits<double>::quiet_NaN());
}

}  // namespace immerse
