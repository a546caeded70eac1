#include "immerse/scenario/ChannelRun.hpp"

#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

std::vector<Column> ChannelRun::run_columns() const {
  return {{"mean_velocity", "m/s", "mean fluid velocity along the flow (y) over the box"}};
}

// The flow rate through a cross-section over its area: on the periodic y axis every y-face is distinct, and the
// faces tile the box.
void ChannelRun::add_run_values(const SimulationInterface& sim, std::vector<double>& row) const {
  row.push_back(sim.mean_velocity(1));
}

}  // namespace immerse
