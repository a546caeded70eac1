#pragma once
// One axis of the fast-transform Helmholtz/Poisson solvers (docs/theory/conventions.md, "MAC grid and fast
// transforms"): which unknowns along the axis, which real transform diagonalizes the 3-point second difference there,
// and its eigenvalues λ(s) = −(4/h²) sin²(π (s + shift) / period), shift 1 for the sine transforms, period N for a
// periodic axis and 2N on a wall axis. Shared by FftHelmholtzSolver and SlabFftHelmholtzSolver, so that the serial and
// the distributed solves use the same numbers bit for bit.
#include <fftw3.h>

#include <vector>

#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

struct FftAxis {
  int count = 0;                 ///< unknowns along the axis
  int first = 0;                 ///< index of the first one in the layout's array
  fftw_r2r_kind forward{}, backward{};
  double normalization = 1;      ///< N (DFT) or 2N (the others): the factor a round trip multiplies by
  std::vector<double> lambda;    ///< eigenvalue of each transform slot
};

/// Axis `a` (0, 1, 2) of `layout` on `grid`.
FftAxis fft_axis(const Grid& grid, Layout layout, int a);

/// out[i + mx (j + my k)] = 1 / ((α + β (lx[i] + ly[j] + lz[k])) N), 0 where the denominator is 0 (the null mode),
/// for mx × my × mz slots; OpenMP threads when `threaded`.
void tabulate_inverse_symbol(const double* lx, const double* ly, const double* lz, int mx, int my, int mz,
                             double alpha, double beta, double normalization, double* out, bool threaded);

}  // namespace immerse
