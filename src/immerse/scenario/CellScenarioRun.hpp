#pragma once
// The red-cell scenarios: each membrane's row of diagnostics.csv carries the cell's axial and transverse diameters
// (CellDiameters), the axial one along the force (x, rbc_stretch) or the flow (y, rbc_channel).
#include "immerse/scenario/ScenarioRun.hpp"

namespace immerse {

class CellScenarioRun : public ScenarioRun {
 public:
  /// `axis`: the coordinate axis of the axial diameter.
  explicit CellScenarioRun(int axis) : axis_(axis) {}

  std::vector<Column> membrane_columns() const override;
  void add_membrane_values(const std::vector<Vec3>& X, std::vector<double>& row) const override;

 private:
  int axis_;
};

}  // namespace immerse
