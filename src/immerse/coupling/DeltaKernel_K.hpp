#pragma once
// Pointwise one-dimensional discrete delta kernels φ(r), r = distance / h, paper §2.2.
// The 3D kernel is the tensor product D_h(x) = φ(x/h) φ(y/h) φ(z/h) / h³ (eq. 7).
//
// roma3   — Roma, Peskin & Berger 3-point kernel (eq. 8), support |r| < 3/2:
//             φ(r) = (1 + √(1 − 3r²)) / 3                      |r| ≤ 1/2
//                    (5 − 3|r| − √(1 − 3(1 − |r|)²)) / 6        1/2 ≤ |r| ≤ 3/2
// peskin4 — Peskin's 4-point kernel, support |r| < 2:
//             φ(r) = (3 − 2|r| + √(1 + 4|r| − 4r²)) / 8         |r| ≤ 1
//                    (5 − 2|r| − √(−7 + 12|r| − 4r²)) / 8       1 ≤ |r| ≤ 2
// Both satisfy, for every shift s, Σ_j φ(s − j) = 1 and Σ_j (s − j) φ(s − j) = 0;
// Σ φ² = 1/2 (roma3), 3/8 (peskin4), and for peskin4 the even and odd sums are 1/2 each.
//
// The *_weights functions give the nonzero weights of one grid line at once: for a point at
// t (in index units) they return the first index i0 and fill w[m] = φ(t − (i0 + m)).
// They share one square root between the points, which is the form the coupler uses.
// Verified by: the study delta_moments (point values; Σφ = 1, first moment 0, Σφ²; grouped weights = φ) and the
// tests DeltaKernel.* (point values, continuity across the branch points).
#include <cmath>

namespace immerse {

inline double roma3_phi(double r) {
  const double a = std::abs(r);
  if (a <= 0.5) return (1.0 + std::sqrt(1.0 - 3.0 * a * a)) / 3.0;
  if (a < 1.5) {
    const double b = 1.0 - a;
    return (5.0 - 3.0 * a - std::sqrt(1.0 - 3.0 * b * b)) / 6.0;
  }
  return 0.0;
}

inline int roma3_first(double t) { return static_cast<int>(std::floor(t + 0.5)) - 1; }

inline int roma3_weights(double t, double w[3]) {
  const int i0 = roma3_first(t);
  const double r = t - (i0 + 1);  // offset from the nearest point, in [-1/2, 1/2]
  const double q = std::sqrt(1.0 - 3.0 * r * r);
  w[0] = (2.0 - 3.0 * r - q) / 6.0;
  w[1] = (1.0 + q) / 3.0;
  w[2] = (2.0 + 3.0 * r - q) / 6.0;
  return i0;
}

inline double peskin4_phi(double r) {
  const double a = std::abs(r);
  if (a <= 1.0) return (3.0 - 2.0 * a + std::sqrt(1.0 + 4.0 * a - 4.0 * a * a)) / 8.0;
  if (a < 2.0) return (5.0 - 2.0 * a - std::sqrt(-7.0 + 12.0 * a - 4.0 * a * a)) / 8.0;
  return 0.0;
}

inline int peskin4_first(double t) { return static_cast<int>(std::floor(t)) - 1; }

inline int peskin4_weights(double t, double w[4]) {
  const int i0 = peskin4_first(t);
  const double r = t - (i0 + 1);  // in [0, 1)
  const double q = std::sqrt(1.0 + 4.0 * r - 4.0 * r * r);
  w[0] = (3.0 - 2.0 * r - q) / 8.0;
  w[1] = (3.0 - 2.0 * r + q) / 8.0;
  w[2] = (1.0 + 2.0 * r + q) / 8.0;
  w[3] = (1.0 + 2.0 * r - q) / 8.0;
  return i0;
}

}  // namespace immerse
