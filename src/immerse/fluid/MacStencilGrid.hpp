#pragma once
// What the MAC stencil kernels need to know about the grid: counts, periodicity, spacing and the wall
// velocities that define the ghost values. Plus the loops over the unknowns of each layout.
//
// Unknowns of velocity component d: every face of its array, except on a wall axis d the two wall faces
// (index 0 and n), which hold the prescribed normal wall velocity.
// Verified by the tests MacOperators.* (the kernels over its unknowns and interior ranges).
#include <algorithm>
#include <array>

#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

struct MacStencilGrid {
  std::array<int, 3> n{};
  std::array<bool, 3> periodic{};
  double h = 1;
  double inv_h = 1, inv_h2 = 1;      // 1/h, 1/h²
  std::array<Vec3, 3> wall_lower{};  ///< velocity of the lower wall of each wall axis (zero: homogeneous)
  std::array<Vec3, 3> wall_upper{};

  /// Homogeneous walls (all wall velocities zero): the operators the fast solvers invert.
  explicit MacStencilGrid(const Grid& g) : n(g.n()), h(g.h()), inv_h(1 / g.h()), inv_h2(1 / (g.h() * g.h())) {
    for (int a = 0; a < 3; ++a) periodic[a] = g.periodic(a);
  }
  MacStencilGrid(const Grid& g, const FluidParams& p) : MacStencilGrid(g) {
    wall_lower = p.wall_lower;
    wall_upper = p.wall_upper;
  }

  /// Whether loops over this grid are worth spreading over OpenMP threads (below ~40³ cells the fork/join
  /// costs more than the work).
  bool threaded() const { return static_cast<long>(n[0]) * n[1] * n[2] >= kMinCellsForThreads; }
  static constexpr long kMinCellsForThreads = immerse::kMinCellsForThreads;

  /// First unknown index of velocity component d along axis a (the end is always n[a], exclusive).
  int first(int d, int a) const { return (a == d && !periodic[a]) ? 1 : 0; }

  /// Faces of component d along a wall axis a, [interior_begin, interior_end), whose six neighbours, the four
  /// faces of each other component around them (advection) and the cell behind them (gradient) are all stored
  /// unknowns: no wall value, ghost value or wall source term (MacStencil_K.hpp). On a periodic axis every face.
  int interior_begin(int d, int a) const { return periodic[a] ? 0 : (a == d ? 2 : 1); }
  int interior_end(int a) const { return periodic[a] ? n[a] : n[a] - 1; }
};

/// Calls f(i, j, k) for every unknown of velocity component d (OpenMP over the two outer axes).
template <class F>
void for_each_face(const MacStencilGrid& g, int d, F&& f) {
  const int i0 = g.first(d, 0), j0 = g.first(d, 1), k0 = g.first(d, 2);
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = k0; k < g.n[2]; ++k)
    for (int j = j0; j < g.n[1]; ++j)
      for (int i = i0; i < g.n[0]; ++i) f(i, j, k);
}

/// Half-open index box [begin[a], end[a]) along each axis.
struct IndexBox {
  std::array<int, 3> begin, end;
};

/// Visits every index of `all`: rows (j, k) inside `fast` along y and z get row(j, k, fast.begin[0],
/// fast.end[0]) for their x-range inside `fast` and point(i, j, k) for the rest; every other row is visited by
/// point() alone (the generic kernels). OpenMP over the two outer axes, like for_each_face. `fast` must lie
/// inside `all`.
template <class Point, class Row>
void for_each_split(const MacStencilGrid& g, const IndexBox& all, const IndexBox& fast, Point&& point, Row&& row) {
  const int i0 = all.begin[0], i1 = all.end[0];
  const int f0 = fast.begin[0], f1 = fast.end[0];
  const bool x_fast = f0 < f1;
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = all.begin[2]; k < all.end[2]; ++k)
    for (int j = all.begin[1]; j < all.end[1]; ++j) {
      const bool fast_row =
          x_fast && j >= fast.begin[1] && j < fast.end[1] && k >= fast.begin[2] && k < fast.end[2];
      if (!fast_row) {
        for (int i = i0; i < i1; ++i) point(i, j, k);
        continue;
      }
      for (int i = i0; i < f0; ++i) point(i, j, k);
      row(j, k, f0, f1);
      for (int i = f1; i < i1; ++i) point(i, j, k);
    }
}

/// Calls row(j, k, box.begin[0], box.end[0]) for every row of the box (OpenMP over the two outer axes).
template <class Row>
void for_each_row(const MacStencilGrid& g, const IndexBox& box, Row&& row) {
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = box.begin[2]; k < box.end[2]; ++k)
    for (int j = box.begin[1]; j < box.end[1]; ++j) row(j, k, box.begin[0], box.end[0]);
}

/// The unknowns of velocity component d, and among them those where the row kernels apply
/// (MacStencilGrid::interior_begin/end).
inline IndexBox face_box(const MacStencilGrid& g, int d) {
  return {{g.first(d, 0), g.first(d, 1), g.first(d, 2)}, g.n};
}
inline IndexBox interior_face_box(const MacStencilGrid& g, int d) {
  IndexBox b = face_box(g, d);
  for (int a = 0; a < 3; ++a) {
    b.begin[a] = std::clamp(g.interior_begin(d, a), b.begin[a], b.end[a]);
    b.end[a] = std::clamp(g.interior_end(a), b.begin[a], b.end[a]);
  }
  return b;
}

/// Calls f(i, j, k) for every cell.
template <class F>
void for_each_cell(const MacStencilGrid& g, F&& f) {
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) f(i, j, k);
}

}  // namespace immerse
