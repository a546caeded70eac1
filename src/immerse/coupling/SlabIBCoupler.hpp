#pragma once
// Force spreading and velocity interpolation of the immersed boundary method (paper §2.2) on a grid cut into slabs of
// z planes over MPI processes (SlabDecomposition.hpp), for the nodes of the membranes each process owns
// (MembraneOwnership.hpp):
//
//   spreading     f(x_ijk) = Σ_l F_l D_h(x_ijk − X_l)               (eq. 6)
//   interpolation U_l      = Σ_ijk u(x_ijk) D_h(x_ijk − X_l) h³       (eq. 14)
//
// with D_h(x) = φ(x/h) φ(y/h) φ(z/h) / h³ (eq. 7) and φ a DeltaKernel (eq. 8 by default), the same weights, wall rules
// and summation order per node as IBCoupler (the shared stencils of IBStencil_K.hpp).
//
// Design. A process's nodes may lie anywhere along z (a membrane is owned by the slab of its centroid and may reach
// into other slabs, on a periodic z across the wrap), so each process spreads into, and interpolates from, a padded
// buffer per velocity component: the planes along z from the lowest to the highest plane any of its nodes' kernels
// touch. A node within the owned cell planes [z0, z1) reaches at most 2 planes beyond them on each side, the kernels'
// half-width (cell-centred components: roma3 1 plane below and above, peskin4 2; faces of u_z: both kernels from face
// z0 − 1 to face z1 + 1), so for membranes inside their slab the buffer is the slab with 2 ghost planes per side; a
// membrane reaching out of its slab widens it by its reach.
// On a periodic z each node's stencil is taken at the image (z + k L_z, k ∈ {−1, 0, 1}) nearest the centre of the
// owned planes, so a membrane across the wrap occupies one contiguous range; on a wall axis the buffer is clipped
// to the stored planes (faces 0 … N_z of u_z, centres 0 … N_z − 1 otherwise), which drops exactly the kernel points
// the serial coupler drops beyond a wall (so ⟨S F, u⟩ h³ = ⟨F, J u⟩ still holds exactly).
//
// Communication. Each call first gathers every process's buffer ranges (MPI_Allgather of six integers); every plane
// of a buffer then belongs to the process holding it (SlabDecomposition::holder, planes wrapped on a periodic z).
// Spreading: each process spreads its nodes in index order into its zeroed buffers, sends each plane to its holder
// (one MPI_Alltoallv), and the holder sets its held planes of the slab force to the sum of the planes it receives,
// added in the order of the senders' ranks (itself included), then of the components and planes. Interpolation: the
// holders send the planes of the slab velocity each buffer needs (one MPI_Alltoallv, the transpose of spreading's)
// and each process interpolates its nodes locally. The slab velocity is read on its held planes only (no ghost
// planes needed; a wall face of u_z holds the wall velocity, as scatter() leaves it).
//
// Results. Interpolation equals IBCoupler's bitwise (the same operands in the same order). Spreading adds the
// contributions at a grid point in another order than IBCoupler (its blocks and colours, then the processes), so
// the two agree to round-off; on a given number of processes the result is bitwise the same in every run (fixed
// order, one thread per process for spreading; interpolation runs in OpenMP threads over nodes, which does not change
// any sum). Both methods are collective over the decomposition's communicator.
// Verified by: the tests ParallelCoupling.* (tests/test_parallel_coupling.cpp, run with 1, 2 and 3 processes: spreading
// and interpolation gathered from the processes against IBCoupler within 1e-12, the adjoint identity, repeated
// calls bitwise equal, the ghost width of nodes inside the slab, and coupled forward Euler steps against the serial
// ones).
#include <array>
#include <span>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/coupling/IndexAxis.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

namespace immerse {

class SlabIBCoupler {
 public:
  /// Couples on `slabs` (kept by reference: it must outlive this object).
  explicit SlabIBCoupler(const SlabDecomposition& slabs, DeltaKernel kernel = RomaPeskin3{});

  /// Eq. (6): overwrites the slab force field f (slab arrays of SlabDecomposition::local_shape; made if not so shaped)
  /// on its held planes with the force density of the nodal forces F at the nodes X of this process (zero on the
  /// other planes). Collective.
  void spread_force(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f);

  /// Eq. (14): U[l] = the slab velocity u (read on its held planes) interpolated to this process's node X[l].
  /// Collective.
  void interpolate_velocity(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U);

  /// The planes along z (global indices, unwrapped on a periodic z) of the padded buffer of velocity component d in
  /// the last call: the ghost width that call needed.
  PlaneRange buffer_planes(int d) const { return {range_[d].begin, range_[d].end}; }
  const SlabDecomposition& decomposition() const { return slabs_; }
  const DeltaKernel& kernel() const { return kernel_; }

 private:
  /// Planes [begin, end) of one component's padded buffer, global indices along z, unwrapped on a periodic z.
  struct Range {
    int begin = 0, end = 0;
  };
  template <class K>
  void prepare(std::span<const Vec3> X);
  void gather_ranges();
  template <class K>
  void spread(std::span<const Vec3> X, std::span<const Vec3> F);
  template <class K>
  void interpolate(std::span<const Vec3> X, std::span<Vec3> U) const;
  /// The global plane of a buffer plane (wrapped on a periodic z).
  int wrap(int d, int plane) const;
  /// Per rank r, the doubles of this process's buffer planes held by r (mine[r]) and of r's buffer planes held by
  /// this process (theirs[r]): what spreading sends to and receives from r (interpolation: the reverse).
  void count_planes(std::vector<int>& mine, std::vector<int>& theirs) const;
  /// The counts and offsets of one MPI_Alltoallv of buffer planes, send_ and recv_ sized for it.
  struct Exchange {
    std::vector<int> send_counts, send_offsets, recv_counts, recv_offsets;
  };
  /// Spreading sends this process's buffer planes to their holders; interpolation (spreading = false) the reverse.
  Exchange plan_exchange(bool spreading);
  /// send_ to recv_ as planned (collective).
  void exchange(const Exchange& e);
  void check_slab(const FaceField& field, const char* what) const;

  const SlabDecomposition& slabs_;
  Grid grid_;
  DeltaKernel kernel_;
  std::array<IndexAxis, 3> axes_;
  int rank_ = 0, size_ = 1;
  std::array<int, 3> planes_{};      ///< planes of each component's global array along z
  std::vector<int> shift_;           ///< per node: the image shift k N_z of its z coordinate
  std::array<Range, 3> range_{};     ///< this process's buffer planes per component
  std::vector<Range> all_ranges_;    ///< every process's, 3 per rank
  std::array<Array3, 3> buffer_;     ///< the padded buffers
  std::vector<double> send_, recv_;  ///< message buffers
};

}  // namespace immerse
