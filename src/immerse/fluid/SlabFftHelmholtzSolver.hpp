#pragma once
// Distributed fast-transform solver for (α I + β ∇_h²) x = b on one MAC layout: the mathematics of
// FftHelmholtzSolver on a grid cut into slabs of z planes, one slab per MPI process (FFTW-MPI).
//
// Per axis a real transform diagonalizes the 3-point second difference (docs/theory/conventions.md, "MAC grid and
// fast transforms"): R2HC / HC2R on a periodic axis, RODFT00 on the N−1 interior faces of a face-normal velocity
// on a wall axis, RODFT10 / RODFT01 for a cell-centred velocity, REDFT10 / REDFT01 for the pressure; in transform
// space x̂(k) = b̂(k) / (α + β (λ_x(i) + λ_y(j) + λ_z(k))), and 0 where the denominator is 0 (the constant null mode).
//
// Decomposition. The unknowns form an M_x × M_y × M_z block (count(); first() is the index of its first point in the
// layout's array). z is the slowest axis of Array3 and the first FFTW dimension, so process r owns the planes
//   z_r = z0_r … z0_r + n_r − 1   (n_r = local_planes(), z0_r = first_plane(), FFTW's block distribution:
//                                   ⌈M_z / P⌉ planes per process, the last processes fewer or none),
// in its own Array3 of local_shape() = {S_x, S_y, n_r}: plane k of it is plane first().z + z0_r + k of the layout's
// global array, with that array's full x and y extent (S_x, S_y; wall faces of x or y included and left untouched).
// The forward 3D r2r transform (fftw_mpi_plan_many_r2r; FFTW_ESTIMATE, the same plan on every run, unless the caller
// asks FftPlanning::Measure, whose timings FFTW-MPI reduces over the processes so that all choose alike) returns the
// coefficients in the same distribution, so each process divides its planes k by the symbol at global k = z0_r + k.
// FFTW-MPI transposes through an internal buffer of fftw_mpi_local_size_3d values, which can exceed n_r M_y M_x.
// More processes than planes (P > M_z) is refused (std::invalid_argument). A caller that shares planes between
// layouts may instead give the block size B itself: process r then owns the planes [r B, min((r + 1) B, M_z)) (FFTW's
// block distribution with that block; possibly none), for any B with P B ≥ M_z.
//
// One thread per process; FFTW-MPI's functions need fftw_mpi_init() (called here, once per process suffices) after
// MPI_Init, and the program calls fftw_mpi_cleanup() before MPI_Finalize, after the last solver is destroyed.
// Construction and solve() are collective: every process of the communicator calls them, in the same order.
// Verified by: the tests SlabFftHelmholtzSolver.* (tests/test_parallel_slab_solver.cpp, run by ctest with 1, 2 and 3
// processes: the gathered solution equals FftHelmholtzSolver's within 1e-12 for every layout and boundary kind,
// residual ≤ 1e-11, repeated solves bitwise identical).
#include <array>
#include <cstddef>
#include <limits>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/parallel/Communicator.hpp"

namespace immerse {

class SlabFftHelmholtzSolver {
 public:
  /// Plans the distributed transforms of `layout` on `grid` (collective over `comm`). Throws std::invalid_argument
  /// when `comm` has more processes than the layout has planes of unknowns along z.
  SlabFftHelmholtzSolver(const Grid& grid, Layout layout, Communicator comm);
  /// The same with `block` planes per process (the last ones fewer or none); std::invalid_argument unless
  /// block ≥ 1 and block · P ≥ M_z.
  SlabFftHelmholtzSolver(const Grid& grid, Layout layout, Communicator comm, int block,
                         FftPlanning planning = FftPlanning::Estimate);
  ~SlabFftHelmholtzSolver();
  SlabFftHelmholtzSolver(const SlabFftHelmholtzSolver&) = delete;
  SlabFftHelmholtzSolver& operator=(const SlabFftHelmholtzSolver&) = delete;

  /// Overwrites this process's slab x (shape local_shape()) with its part of the solution of (α I + β ∇_h²) x = b,
  /// b being the values of the slabs on entry. Collective. Wall faces along x or y of the slab are untouched.
  void solve(Array3& x, double alpha, double beta);
  /// The same on planes [plane0, plane0 + local_planes()) of x, an array with the slab's x and y extent and any
  /// further planes (ghost planes), which are untouched.
  void solve(Array3& x, int plane0, double alpha, double beta);

  Layout layout() const { return layout_; }
  const Communicator& communicator() const { return comm_; }
  /// Global number of unknowns along each axis and the index of the first one in the layout's array.
  const std::array<int, 3>& count() const { return m_; }
  const std::array<int, 3>& first() const { return lo_; }
  /// This process's planes of unknowns along z: how many, and the global index of the first among the unknowns.
  int local_planes() const { return local_planes_; }
  int first_plane() const { return first_plane_; }
  /// Shape of this process's slab: the layout array's x and y extent, local_planes() planes.
  std::array<int, 3> local_shape() const { return {shape_[0], shape_[1], local_planes_}; }
  /// Index along z, in the layout's global array, of the slab's plane 0.
  int first_array_plane() const { return lo_[2] + first_plane_; }

 private:
  /// Plans with FFTW's default block (block = 0) or the given one.
  void plan(const Grid& grid, int block, FftPlanning planning);
  /// Tabulates 1 / ((α + β Σλ) N) (0 for a zero denominator) for the local planes.
  void set_symbol(double alpha, double beta);

  Layout layout_;
  Communicator comm_;
  std::array<int, 3> m_{}, lo_{}, shape_{};
  int local_planes_ = 0, first_plane_ = 0;
  std::array<std::vector<double>, 3> lambda_;  // eigenvalues of the 3-point second difference per axis (global)
  double normalization_ = 1;                   // product over axes of N (DFT) or 2N (others)
  std::vector<double> inverse_;                // 1 / ((α + β Σλ) N) per local transform slot
  double alpha_ = std::numeric_limits<double>::quiet_NaN(), beta_ = alpha_;
  double* buf_ = nullptr;  // FFTW-MPI's work buffer (its own allocation size)
  fftw_plan_s* forward_ = nullptr;
  fftw_plan_s* backward_ = nullptr;
};

}  // namespace immerse
