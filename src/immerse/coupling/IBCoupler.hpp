#pragma once
// Force spreading and velocity interpolation of the immersed boundary method, paper §2.2:
//
//   spreading     f(x_ijk) = Σ_l F_l D_h(x_ijk − X_l)               (eq. 6)
//   interpolation U_l      = Σ_ijk u(x_ijk) D_h(x_ijk − X_l) h³       (eq. 14)
//
// with D_h(x) = φ(x/h) φ(y/h) φ(z/h) / h³ (eq. 7) and φ a DeltaKernel (eq. 8 by default).
// F_l is the nodal force in newtons (the paper's f_l Δq Δr Δs); f is a force density (N/m³).
// On the MAC grid (Grid.hpp) each velocity component d is spread to, and interpolated from,
// its own face positions x_ijk = Grid::face_position(d, i, j, k). Periodic axes wrap around.
//
// Walls. On a wall axis the face-normal component has faces on the two walls (indices 0 and n,
// velocity prescribed; the fluid solver ignores force stored there) and the tangential
// components are cell-centred. Kernel points that fall outside the stored array (beyond a
// wall) are dropped, identically in spreading and interpolation. So J = S* exactly in the
// h³-weighted inner product over all stored points, ⟨S F, u⟩ h³ = ⟨F, J u⟩, for every node
// position. The price: within the kernel reach of a wall the moment conditions are lost —
// force spread beyond the wall disappears, Σ f h³ ≠ F and Σ J u ≠ u for a uniform u. The
// stored total force is exact for nodes at distance ≥ (support − 1/2) h from every wall, and
// the force the fluid feels (wall faces excluded) for distance ≥ support h.
//
// The arrays X, F, U hold the nodes of all membranes concatenated. Nodes beyond a wall or
// non-finite throw SimulationError naming the node index (check_nodes_in_domain).
//
// Threads: interpolation runs in parallel over nodes. Spreading sorts the nodes into blocks of
// the (y, z) plane at least one kernel width wide, coloured in a 2 x 2 pattern; blocks of one
// colour write to disjoint grid points and run in parallel, each adding its nodes in index
// order. The result is bitwise independent of the number of threads. After the first call
// with a given number of nodes neither method allocates.
// Verified by: the studies ib_adjointness (⟨S F, u⟩ h³ = ⟨F, J u⟩, 8 boundary combinations × 2 kernels) and
// ib_interpolation_order (order ≥ 1.9; total force and torque of spreading), and the tests IBCoupler.*.
#include <array>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/coupling/IndexAxis.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

class IBCoupler {
 public:
  IBCoupler(const Grid& grid, DeltaKernel kernel = RomaPeskin3{});

  /// Eq. (6): overwrites f (shaped like FaceField(grid)) with the force density of the nodal
  /// forces F at the nodes X.
  void spread_force(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f);

  /// Eq. (14): U[l] = velocity u interpolated to node X[l].
  void interpolate_velocity(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U) const;

  const Grid& grid() const { return grid_; }
  const DeltaKernel& kernel() const { return kernel_; }

 private:
  template <class K>
  void spread(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f);
  template <class K>
  void interpolate(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U) const;
  template <class K>
  void sort_into_blocks(std::span<const Vec3> X);
  void check_shape(const FaceField& field, const char* what) const;

  Grid grid_;
  DeltaKernel kernel_;
  std::array<IndexAxis, 3> axes_;  ///< the grid axes in index units
  std::array<int, 2> blocks_{1, 1};      ///< blocks along y and z (each 1 or even)
  std::array<int, 2> block_size_{1, 1};  ///< grid points per block along y and z
  std::vector<int> block_start_;         ///< nodes of block b: block_nodes_[block_start_[b] .. block_start_[b+1])
  std::vector<int> block_nodes_;
  std::vector<int> block_of_node_;
};

}  // namespace immerse
