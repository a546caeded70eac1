#include "immerse/parallel/HaloExchange.hpp"

#include <mpi.h>

#include <cstddef>
#include <stdexcept>
#include <string>

namespace immerse {

namespace {

/// The ghost plane `ghost` beyond a wall from the plane `inner` next to it (see the header).
void wall_ghost(Array3& a, Layout layout, int ghost, int inner, const Vec3& wall) {
  const std::size_t n = static_cast<std::size_t>(a.nx()) * a.ny();
  double* const g = a.data() + a.index(0, 0, ghost);
  const double* const u = a.data() + a.index(0, 0, inner);
  if (layout == Layout::Pressure) {
    for (std::size_t q = 0; q < n; ++q) g[q] = u[q];
  } else if (layout == Layout::VelocityZ) {
    for (std::size_t q = 0; q < n; ++q) g[q] = wall[2];
  } else {
    const double w = wall[static_cast<int>(layout)];
    for (std::size_t q = 0; q < n; ++q) g[q] = 2.0 * w - u[q];
  }
}

}  // namespace

HaloExchange::HaloExchange(const SlabDecomposition& slabs, const Vec3& wall_lower, const Vec3& wall_upper)
    : slabs_(slabs), wall_lower_(wall_lower), wall_upper_(wall_upper) {}

void HaloExchange::exchange(Array3& a, Layout layout) const {
  if (a.shape() != slabs_.local_shape(layout))
    throw std::invalid_argument("HaloExchange::exchange: the array is not a slab array of the layout");
  const PlaneRange own = slabs_.owned(layout);
  const int lo = own.begin - slabs_.offset(), hi = own.end - slabs_.offset();  // local owned planes [lo, hi)
  const int n = a.nx() * a.ny();
  const MPI_Comm comm = slabs_.communicator().comm();
  const int down = slabs_.lower_neighbor(), up = slabs_.upper_neighbor();
  double* const plane_lo = a.data() + a.index(0, 0, lo);
  double* const plane_hi = a.data() + a.index(0, 0, hi - 1);
  double* const ghost_lo = a.data() + a.index(0, 0, lo - 1);
  double* const ghost_hi = a.data() + a.index(0, 0, hi);
  check_mpi(MPI_Sendrecv(plane_lo, n, MPI_DOUBLE, down, 0, ghost_hi, n, MPI_DOUBLE, up, 0, comm, MPI_STATUS_IGNORE),
        "MPI_Sendrecv");
  check_mpi(MPI_Sendrecv(plane_hi, n, MPI_DOUBLE, up, 1, ghost_lo, n, MPI_DOUBLE, down, 1, comm, MPI_STATUS_IGNORE),
        "MPI_Sendrecv");
  if (down == MPI_PROC_NULL) wall_ghost(a, layout, lo - 1, lo, wall_lower_);
  if (up == MPI_PROC_NULL) wall_ghost(a, layout, hi, hi - 1, wall_upper_);
}

}  // namespace immerse
