#include "immerse/membrane/CellDiameters.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace immerse {

CellDiameters cell_diameters(const std::vector<Vec3>& X, int axis) {
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& p : X)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  return {hi[axis] - lo[axis], std::max(hi[a] - lo[a], hi[b] - lo[b])};
}

}  // namespace immerse
