#pragma once
// One axis of a Grid in index units, as the delta-kernel stencils need it: node coordinates
// become face indices with a multiplication (no division), wrapped on periodic axes.
#include <cmath>

#include "immerse/grid/Grid.hpp"

namespace immerse {

struct IndexAxis {
  double origin, inv_h, length;
  int n;
  bool periodic;

  IndexAxis(const Grid& g, int axis)
      : origin(g.origin()[axis]), inv_h(1.0 / g.h()), length(g.length(axis)), n(g.n(axis)),
        periodic(g.periodic(axis)) {}

  /// Coordinate of x in index units of the faces normal to this axis (face i at i), wrapped into
  /// [0, n] on a periodic axis. Cell centres are at this minus 1/2.
  double face_coordinate(double x) const {
    double xr = x - origin;
    if (periodic && !(xr >= 0 && xr < length)) {  // (fmod would return xr unchanged inside the box)
      xr = std::fmod(xr, length);                  // exact, also for coordinates many periods away
      if (xr < 0) xr += length;
    }
    return xr * inv_h;
  }
  /// Number of stored faces normal to this axis (Grid::face_shape).
  int faces() const { return periodic ? n : n + 1; }
};

}  // namespace immerse
