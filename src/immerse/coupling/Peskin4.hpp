#pragma once
// Peskin's 4-point discrete delta kernel (formula in DeltaKernel_K.hpp).
// Verified by: the study delta_moments (peskin4) and the tests DeltaKernel.*.
#include "immerse/coupling/DeltaKernel_K.hpp"

namespace immerse {

struct Peskin4 {
  static constexpr const char* name = "peskin4";
  static constexpr int width = 4;         ///< grid points per axis with nonzero weight
  static constexpr double support = 2.0;  ///< φ(r) = 0 for |r| >= support
  static double phi(double r) { return peskin4_phi(r); }
  static int first(double t) { return peskin4_first(t); }
  static int weights(double t, double w[width]) { return peskin4_weights(t, w); }
};

}  // namespace immerse
