#pragma once
// The fluid grid cut into slabs of z planes, one per MPI process, and the slab arrays of each MAC layout.
//
// Cells. With P processes and N_z cells along z, process r owns the cell planes z0 … z1 − 1, z0 = r B,
// z1 = min((r + 1) B, N_z), B = ⌈N_z / P⌉ (block()). Every process must own at least one cell plane, and at least two
// when z is a wall axis and it is the last one (std::invalid_argument otherwise).
//
// Unknowns. Each layout's planes of unknowns along z are shared in blocks of the same B: the planes of unknown
// indices [r B, (r + 1) B) (FFTW's block distribution with block B, which SlabFftHelmholtzSolver is given), so each
// process solves on the planes it owns. For u_x, u_y, the pressure and u_z on a periodic z these are the cell planes
// z0 … z1 − 1 (u_z on face z: the lower face of cell z); for u_z on a wall axis, whose unknowns are the faces
// 1 … N_z − 1, they are the faces z0 + 1 … min(z1, N_z − 1), the upper faces of the owned cells below the upper wall.
//
// Slab arrays. Every layout's slab array has the layout's full x and y extent and the z1 − z0 + 3 planes of global
// index z0 − 1 … z1 + 1 (local plane k is global plane k + offset(), offset() = z0 − 1, the same for every layout,
// so the MAC kernels index all layouts' slabs alike). They hold the owned planes and one ghost plane on each side of
// them (HaloExchange fills it); the one plane left over (z1 + 1 for cell layouts, z0 − 1 for u_z on a wall axis) is
// not used. held(layout) are the planes of the layout's global array that scatter() writes and gather() collects:
// the owned ones, plus the wall faces of u_z (0 on the first process, N_z on the last) on a wall axis; holder() names
// the process holding a given plane, so every plane of every layout has exactly one.
// Verified by: the tests HaloExchange.* (scatter and gather) and ParallelFluidStep.*
// (tests/test_parallel_fluid_step.cpp, 1, 2 and 3 processes), and ParallelCoupling.HolderOfEveryPlane (holder()).
#include <array>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/parallel/Communicator.hpp"

namespace immerse {

/// Half-open range [begin, end) of z planes (global indices into a layout's array).
struct PlaneRange {
  int begin = 0, end = 0;
  int count() const { return end - begin; }
};

class SlabDecomposition {
 public:
  /// Cuts `grid` over the processes of `comm` (collective only in that every process must make the same one).
  SlabDecomposition(const Grid& grid, Communicator comm);

  const Grid& grid() const { return grid_; }
  const Communicator& communicator() const { return comm_; }
  /// Cell planes per process (the last ones fewer).
  int block() const { return block_; }
  /// This process's cell planes [z0, z1).
  PlaneRange cells() const { return {z0_, z1_}; }
  /// This process's planes of unknowns of `layout`.
  PlaneRange owned(Layout layout) const;
  /// The planes of the global array of `layout` that this process scatters and gathers.
  PlaneRange held(Layout layout) const;
  /// The rank whose held(layout) contains the global plane `plane` (0 ≤ plane < the layout's planes along z).
  int holder(Layout layout, int plane) const;
  /// Global index of local plane 0 of every slab array.
  int offset() const { return z0_ - 1; }
  /// Shape of the slab array of `layout` (layout's x and y extent, z1 − z0 + 3 planes).
  std::array<int, 3> local_shape(Layout layout) const;
  /// A zero slab array of `layout`.
  Array3 make(Layout layout) const;
  /// Whether this process holds the lowest (first) or highest (last) cell planes.
  bool first() const { return rank_ == 0; }
  bool last() const { return rank_ == size_ - 1; }
  /// The ranks of the processes holding the planes just below and above this one's (with wrap on a periodic z;
  /// MPI_PROC_NULL beyond a wall).
  int lower_neighbor() const;
  int upper_neighbor() const;

  /// Copies the held planes of the global array `global` of `layout` into the slab array `local` (made if its shape
  /// is not local_shape()); other planes of `local` are left as they are. Not collective.
  void scatter(const Array3& global, Layout layout, Array3& local) const;
  /// The global array of `layout` assembled from the held planes of every process's slab, on every process.
  /// Collective.
  Array3 gather(const Array3& local, Layout layout) const;

 private:
  Grid grid_;
  Communicator comm_;
  int rank_ = 0, size_ = 1;
  int block_ = 0, z0_ = 0, z1_ = 0;
};

}  // namespace immerse
