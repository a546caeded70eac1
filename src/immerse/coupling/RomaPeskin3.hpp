#pragma once
// Roma–Peskin–Berger 3-point discrete delta kernel, paper eq. (8) (the default kernel).
// Verified by: the study delta_moments (roma3) and the tests DeltaKernel.*.
#include "immerse/coupling/DeltaKernel_K.hpp"

namespace immerse {

struct RomaPeskin3 {
  static constexpr const char* name = "roma3";
  static constexpr int width = 3;         ///< grid points per axis with nonzero weight
  static constexpr double support = 1.5;  ///< φ(r) = 0 for |r| >= support
  static double phi(double r) { return roma3_phi(r); }
  static int first(double t) { return roma3_first(t); }
  static int weights(double t, double w[width]) { return roma3_weights(t, w); }
};

}  // namespace immerse
