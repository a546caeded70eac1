#pragma once
// Cholesky factorization M = L L^T of a small dense symmetric matrix and the solve with it: the normal equations of
// the small least-squares fits (CurvatureFit's local quartic, GuessErrorPredictor's recurrence). Row-major n x n with
// row stride `stride`, in place: the lower triangle becomes L.
#include <cmath>

namespace immerse {

/// Factors M; false as soon as a squared pivot d fails pivot_ok(d, M's diagonal entry) (M is then partly overwritten).
template <class PivotOk>
bool cholesky_factor(double* M, int n, int stride, PivotOk pivot_ok) {
  for (int j = 0; j < n; ++j) {
    double d = M[j * stride + j];
    for (int k = 0; k < j; ++k) d -= M[j * stride + k] * M[j * stride + k];
    if (!pivot_ok(d, M[j * stride + j])) return false;
    d = std::sqrt(d);
    M[j * stride + j] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = M[i * stride + j];
      for (int k = 0; k < j; ++k) s -= M[i * stride + k] * M[j * stride + k];
      M[i * stride + j] = s / d;
    }
  }
  return true;
}

/// Solves L L^T x = r in place (n values) with the factor from cholesky_factor.
inline void cholesky_solve(const double* L, int n, int stride, double* r) {
  for (int i = 0; i < n; ++i) {
    double s = r[i];
    for (int k = 0; k < i; ++k) s -= L[i * stride + k] * r[k];
    r[i] = s / L[i * stride + i];
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = r[i];
    for (int k = i + 1; k < n; ++k) s -= L[k * stride + i] * r[k];
    r[i] = s / L[i * stride + i];
  }
}

}  // namespace immerse
