#include "immerse/app/ChannelRun.hpp"

#include "immerse/simulation/Simulation.hpp"

namespace immerse {

std::vector<Column> ChannelRun::run_columns() const {
  return {{"mean_velocity", "m/s", "mean fluid velocity along the flow (y) over the box"}};
}

// The flow rate through a cross-section over its area: on the periodic y axis every y-face is distinct, and the
// faces tile the box.
void ChannelRun::add_run_values(const Simulation& sim, std::vector<double>& row) const {
  const auto& v = sim.op().fluid_state().u[1].values();
  double sum = 0;
  for (double x : v) sum += x;
  row.push_back(sum / double(v.size()));
}

}  // namespace immerse
