#pragma once
// rbc_channel (§4.4): the cells' diameters along the flow (y) and the mean flow velocity in diagnostics.csv.
#include "immerse/scenario/CellScenarioRun.hpp"

namespace immerse {

class ChannelRun : public CellScenarioRun {
 public:
  ChannelRun() : CellScenarioRun(1) {}

  std::vector<Column> run_columns() const override;
  void add_run_values(const SimulationInterface& sim, std::vector<double>& row) const override;
};

}  // namespace immerse
