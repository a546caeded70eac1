#pragma once
// Diameters of a deformed cell measured along an axis (§4.3, notes): the axial diameter is the largest extent
// of the nodes along `axis` (the force axis of the optical tweezers, the flow direction in a channel); the
// transverse diameter is the largest extent along either of the two other coordinate axes. For the stretched
// cell of §4.3, whose disc lies in x-y and stays thin along z, that is its extent along y, in the plane of the disc.
// Verified by the test RbcChannel.ThirtyTwoCellsInAPoiseuilleDuctWithTheirDiagnostics (the axial diameter of each
// undeformed cell is its 7.82 um disc diameter).
#include <vector>

#include "immerse/core/Vec3.hpp"

namespace immerse {

struct CellDiameters {
  double axial = 0, transverse = 0;  ///< m
};

CellDiameters cell_diameters(const std::vector<Vec3>& X, int axis);

}  // namespace immerse
