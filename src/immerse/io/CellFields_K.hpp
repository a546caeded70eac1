#pragma once
// Pointwise kernels moving MAC-grid data (Grid.hpp layout) to cell centres for output.
#include <array>

#include "immerse/core/Array3.hpp"

namespace immerse::io {

/// Velocity component d at the centre of cell (i, j, k): the mean of the two faces normal to d that bound the
/// cell. On a periodic axis the upper face of the last cell is face 0; on a wall axis it is face n.
inline double face_to_cell_K(const Array3& ud, int d, int n_d, bool periodic_d, int i, int j, int k) {
  std::array<int, 3> up{i, j, k};
  up[d] += 1;
  if (periodic_d && up[d] == n_d) up[d] = 0;
  return 0.5 * (ud(i, j, k) + ud(up[0], up[1], up[2]));
}

/// Derivative along axis e of the cell-centred field c at cell (i, j, k), second order: central differences,
/// wrapped on a periodic axis; in the first and last cell next to a wall the one-sided
/// (-3 c_0 + 4 c_1 - c_2) / (2h) (a wall axis with 2 cells falls back to (c_1 - c_0) / h).
inline double cell_derivative_K(const Array3& c, int e, int n_e, bool periodic_e, double h, int i, int j, int k) {
  const std::array<int, 3> at{i, j, k};
  const auto v = [&](int m) {
    std::array<int, 3> q = at;
    q[e] = m;
    return c(q[0], q[1], q[2]);
  };
  const int m = at[e];
  if (periodic_e) return (v(m + 1 == n_e ? 0 : m + 1) - v(m == 0 ? n_e - 1 : m - 1)) / (2 * h);
  if (n_e < 3) return (v(1) - v(0)) / h;
  if (m == 0) return (-3 * v(0) + 4 * v(1) - v(2)) / (2 * h);
  if (m == n_e - 1) return (3 * v(m) - 4 * v(m - 1) + v(m - 2)) / (2 * h);
  return (v(m + 1) - v(m - 1)) / (2 * h);
}

}  // namespace immerse::io
