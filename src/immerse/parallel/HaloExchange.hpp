#pragma once
// Fills the ghost planes of a slab array (SlabDecomposition): the plane just below and the plane just above the
// process's owned planes of a layout.
//
// Between processes (and across the periodic wrap of z, a process with itself when it is alone) the ghost plane is
// the neighbour's owned plane, sent with MPI_Sendrecv: first every process sends its lowest owned plane down, then
// its highest up. Beyond a wall along z the ghost takes the boundary values of the MAC kernels (MacStencil_K.hpp):
// for u_x and u_y, cell-centred along z, u_g = 2 u_w − u_0 (u_w the wall's velocity component, u_0 the first plane);
// for u_z the wall face itself, the normal wall velocity; for the pressure the copy p_g = p_0 (homogeneous Neumann).
// So the kernels read the same values on the slabs as on the whole grid.
// Collective: every process calls exchange() for the same layouts in the same order.
// Verified by: the tests HaloExchange.* and ParallelFluidStep.* (tests/test_parallel_fluid_step.cpp, 1, 2 and 3
// processes).
#include <array>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

namespace immerse {

class HaloExchange {
 public:
  /// Exchanges over `slabs` (kept by reference: it must outlive this object); wall_lower and wall_upper are the
  /// velocities of the walls at the lower and upper end of z (ignored on a periodic z).
  HaloExchange(const SlabDecomposition& slabs, const Vec3& wall_lower, const Vec3& wall_upper);

  /// Fills the two ghost planes of the slab array `a` of `layout`.
  void exchange(Array3& a, Layout layout) const;

 private:
  const SlabDecomposition& slabs_;
  Vec3 wall_lower_, wall_upper_;
};

}  // namespace immerse
