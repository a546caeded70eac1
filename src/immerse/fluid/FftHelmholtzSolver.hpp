#pragma once
// Direct fast-transform solver for (α I + β ∇_h²) x = b on one MAC layout (paper end of §3: the three Helmholtz
// problems of (9) and the Poisson problem (11) are solved by fast transforms; we use FFTW instead of FISHPACK).
//
// The 7-point Laplacian is separable, and on each axis one real transform diagonalizes its 3-point part
// (docs/theory/conventions.md, "MAC grid and fast transforms"), with N cells of size h on that axis:
//   periodic axis                              R2HC / HC2R, N points          λ = −(4/h²) sin²(π k/N)
//   wall axis, face-normal velocity            RODFT00 on the N−1 interior    λ = −(4/h²) sin²(π k/2N), k = 1..N−1
//   wall axis, cell-centred velocity (ghost)   RODFT10 / RODFT01, N           λ = −(4/h²) sin²(π k/2N), k = 1..N
//   wall axis, pressure (Neumann)              REDFT10 / REDFT01, N           λ = −(4/h²) sin²(π k/2N), k = 0..N−1
// In half-complex order slot s holds frequency s or N−s; sin² is the same for both, so λ(s) = −(4/h²) sin²(π s/N).
// The operator is homogeneous: wall values must already be in b. x = b / (α + β Σλ) in transform space; a zero
// denominator (the constant null mode of the periodic/Neumann Poisson problem) gives a zero coefficient. The
// factors 1/(α + β Σλ) are tabulated for the last (α, β) (a time step changes them; the step after uses the table).
//
// One in-place 3D r2r plan pair per solver, created once (see FftPlanning); at or above
// MacStencilGrid::kMinCellsForThreads unknowns a second pair for omp_get_max_threads() (at construction) FFTW threads,
// executed whenever OpenMP's thread count is above one when solve() is called (ThreadGovernor may change it). The plans work
// on an internal buffer (the unknowns copied in and out), or, for a solver made for one array whose unknowns are
// the whole array (every layout but a face-normal component on a wall axis), on that array itself. Not reentrant.
// SlabFftHelmholtzSolver distributes the same transforms (FftAxis) over MPI processes.
// Verified by: the study fluid_solvers (residual of every Helmholtz/Poisson solve, every layout and boundary
// combination, ≤ 1e-11) and the tests FftHelmholtzSolver.* (the tabulated eigenvectors, a manufactured Helmholtz solution).
#include <array>
#include <limits>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/grid/Grid.hpp"

struct fftw_plan_s;  // FFTW's plan type (fftw_plan is a pointer to it)

namespace immerse {

/// How FFTW chooses its plans. Estimate plans instantly by FFTW's heuristics: the same plan in every process and
/// for every thread count, so results are bitwise reproducible (a simulation's default, `fluid.fft_planning`).
/// Measure times candidate algorithms (faster transforms, planning costs up to seconds): on a machine whose load
/// varies the timings, and so the plans and their round-off, can differ from one run to the next.
enum class FftPlanning { Estimate, Measure };

/// Which unknowns a solver works on: velocity component 0, 1, 2 (faces), or the cell-centred pressure.
enum class Layout { VelocityX = 0, VelocityY = 1, VelocityZ = 2, Pressure = 3 };

inline Layout velocity_layout(int d) { return static_cast<Layout>(d); }

class FftHelmholtzSolver {
 public:
  /// With `in_place`, a solver that only ever solves in that array (whose values planning may overwrite): it
  /// transforms the array itself when its unknowns are the whole array, saving two copies per solve.
  FftHelmholtzSolver(const Grid& grid, Layout layout, FftPlanning planning = FftPlanning::Measure,
             Array3* in_place = nullptr);
  ~FftHelmholtzSolver();
  FftHelmholtzSolver(const FftHelmholtzSolver&) = delete;
  FftHelmholtzSolver& operator=(const FftHelmholtzSolver&) = delete;

  /// Overwrites the unknowns of x (shape of the layout: face_shape(d) or cell_shape) with the solution of
  /// (α I + β ∇_h²) x = b, b being the values of x on entry. Wall faces of a face-normal layout are untouched.
  /// A solver made `in_place` for an array accepts only that array (std::logic_error otherwise).
  void solve(Array3& x, double alpha, double beta);

  /// Runs only the forward and backward transforms on the work array (reference cost for benchmarks).
  void transform_round_trip();

  Layout layout() const { return layout_; }
  /// Number of unknowns along each axis and the index of the first one in the layout's array.
  const std::array<int, 3>& count() const { return m_; }
  const std::array<int, 3>& first() const { return lo_; }

 private:
  /// Tabulates 1 / ((α + β Σλ) N) (0 for a zero denominator) for this α, β.
  void set_symbol(double alpha, double beta);

  Layout layout_;
  std::array<int, 3> m_{}, lo_{};
  std::array<std::vector<double>, 3> lambda_;  // eigenvalues of the 3-point second difference per axis
  double normalization_ = 1;                   // product over axes of N (DFT) or 2N (others)
  std::vector<double> inverse_;                // 1 / ((α + β Σλ) N) per transform slot, for alpha_, beta_
  double alpha_ = std::numeric_limits<double>::quiet_NaN(), beta_ = alpha_;
  bool threaded_ = false;
  double* buf_ = nullptr;      // the work buffer, or null when working in place
  Array3* target_ = nullptr;   // the array solved in place, if any
  double* data_ = nullptr;     // where the transforms run: buf_ or target_'s data
  /// Which plan pair solve() runs: 0 the one-thread pair, 1 the threaded pair.
  int plan_index() const;
  fftw_plan_s* forward_[2] = {nullptr, nullptr};  // [0] one thread, [1] threaded (if planned)
  fftw_plan_s* backward_[2] = {nullptr, nullptr};
};

}  // namespace immerse
