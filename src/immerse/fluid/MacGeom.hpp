#pragma once
// What the MAC stencil kernels need to know about the grid: counts, periodicity, spacing and the wall
// velocities that define the ghost values. Plus the loops over the unknowns of each layout.
//
// Unknowns of velocity component d: every face of its array, except on a wall axis d the two wall faces
// (index 0 and n), which hold the prescribed normal wall velocity.
#include <array>

#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

struct MacGeom {
  std::array<int, 3> n{};
  std::array<bool, 3> periodic{};
  double h = 1;
  double inv_h = 1, inv_h2 = 1;      // 1/h, 1/h²
  std::array<Vec3, 3> wall_lower{};  ///< velocity of the lower wall of each wall axis (zero: homogeneous)
  std::array<Vec3, 3> wall_upper{};

  /// Homogeneous walls (all wall velocities zero): the operators the fast solvers invert.
  explicit MacGeom(const Grid& g) : n(g.n()), h(g.h()), inv_h(1 / g.h()), inv_h2(1 / (g.h() * g.h())) {
    for (int a = 0; a < 3; ++a) periodic[a] = g.periodic(a);
  }
  MacGeom(const Grid& g, const FluidParams& p) : MacGeom(g) {
    wall_lower = p.wall_lower;
    wall_upper = p.wall_upper;
  }

  /// Whether loops over this grid are worth spreading over OpenMP threads (below ~40³ cells the fork/join
  /// costs more than the work).
  bool threaded() const { return static_cast<long>(n[0]) * n[1] * n[2] >= kMinCellsForThreads; }
  static constexpr long kMinCellsForThreads = 65536;

  /// First unknown index of velocity component d along axis a (the end is always n[a], exclusive).
  int first(int d, int a) const { return (a == d && !periodic[a]) ? 1 : 0; }
};

/// Calls f(i, j, k) for every unknown of velocity component d (OpenMP over the two outer axes).
template <class F>
void for_each_face(const MacGeom& g, int d, F&& f) {
  const int i0 = g.first(d, 0), j0 = g.first(d, 1), k0 = g.first(d, 2);
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = k0; k < g.n[2]; ++k)
    for (int j = j0; j < g.n[1]; ++j)
      for (int i = i0; i < g.n[0]; ++i) f(i, j, k);
}

/// Calls f(i, j, k) for every cell.
template <class F>
void for_each_cell(const MacGeom& g, F&& f) {
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) f(i, j, k);
}

}  // namespace immerse
