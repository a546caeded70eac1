#include "immerse/fluid/FftAxis.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>

namespace immerse {

FftAxis fft_axis(const Grid& grid, Layout layout, int a) {
  const int comp = static_cast<int>(layout);  // 3: pressure
  const int n = grid.n(a);
  const double h = grid.h();
  FftAxis axis;
  double shift = 0;  // eigen frequency of slot s is s + shift; the period is `period` slots
  double period = n;
  if (grid.periodic(a)) {
    axis.count = n;
    axis.forward = FFTW_R2HC;
    axis.backward = FFTW_HC2R;
    axis.normalization = n;
  } else {
    period = 2.0 * n;
    axis.normalization = 2.0 * n;
    if (comp == a) {  // face-normal: the N−1 interior faces, DST-I
      axis.count = n - 1;
      axis.first = 1;
      axis.forward = axis.backward = FFTW_RODFT00;
      shift = 1;
    } else if (comp < 3) {  // cell-centred velocity with ghost 2u_w − u_0: DST-II / DST-III
      axis.count = n;
      axis.forward = FFTW_RODFT10;
      axis.backward = FFTW_RODFT01;
      shift = 1;
    } else {  // pressure, homogeneous Neumann: DCT-II / DCT-III
      axis.count = n;
      axis.forward = FFTW_REDFT10;
      axis.backward = FFTW_REDFT01;
    }
  }
  axis.lambda.resize(static_cast<std::size_t>(axis.count));
  for (int s = 0; s < axis.count; ++s) {
    const double sn = std::sin(std::numbers::pi * (s + shift) / period);
    axis.lambda[static_cast<std::size_t>(s)] = -4.0 / (h * h) * sn * sn;
  }
  return axis;
}

void tabulate_inverse_symbol(const double* lx, const double* ly, const double* lz, int mx, int my, int mz,
                             double alpha, double beta, double normalization, double* out, bool threaded) {
#pragma omp parallel for collapse(2) schedule(static) if (threaded)
  for (int k = 0; k < mz; ++k)
    for (int j = 0; j < my; ++j) {
      double* const row = out + mx * (j + my * static_cast<std::size_t>(k));
      for (int i = 0; i < mx; ++i) {
        const double den = (alpha + beta * (lx[i] + ly[j] + lz[k])) * normalization;
        row[i] = den == 0.0 ? 0.0 : 1.0 / den;
      }
    }
}

}  // namespace immerse
