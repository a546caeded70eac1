#include "immerse/scenario/CellScenarioRun.hpp"

#include "immerse/membrane/CellDiameters.hpp"

namespace immerse {

std::vector<Column> CellScenarioRun::membrane_columns() const {
  return {{"axial_um", "um", "largest extent of the cell along the force (x) or the flow (y)"},
          {"transverse_um", "um", "largest extent along either other coordinate axis"}};
}

void CellScenarioRun::add_membrane_values(const std::vector<Vec3>& X, std::vector<double>& row) const {
  const CellDiameters d = cell_diameters(X, axis_);
  row.insert(row.end(), {d.axial * 1e6, d.transverse * 1e6});
}

}  // namespace immerse
