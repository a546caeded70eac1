#pragma once
// Cell-centred views of a MAC velocity field for visualisation: the velocity (face averages) and the
// vorticity magnitude |curl u| from second-order differences of the cell-centred velocity (CellFields_K.hpp).
#include <array>

#include "immerse/core/Array3.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse::io {

struct CellFields {
  std::array<Array3, 3> velocity;  // component d at cell centres, Grid::cell_shape()
  Array3 vorticity_magnitude;

  static CellFields from_faces(const Grid& grid, const FaceField& u);
};

}  // namespace immerse::io
