#pragma once
// Yeoh membrane, eq. (23):  W = C10 I + C30 I^3,  I = 2 A2 + e^{-2 A1} - 1.
// With C10 = mu0/2, C30 = mu0/30: small-strain shear modulus mu0, area modulus 3 mu0.
// Isotropic stretch lambda: I = 2 lambda^2 + lambda^-4 - 3, tau = 2 (C10 + 3 C30 I^2) (1 - lambda^-6).
// Verified by the tests MembraneMaterial.* (derivatives, isotropic tension, small-strain moduli) and
// CellKinds.YeohConstantsFromMu0OrMu0FromC10, and the studies membrane_inflation and membrane_energy_gradient.
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/EnergyDensity.hpp"

namespace immerse {

struct Yeoh {
  double C10;  ///< N/m
  double C30;  ///< N/m

  Yeoh(double C10_, double C30_) : C10(C10_), C30(C30_) {
    require(C10 > 0, "membrane.law.C10", C10, "> 0");
    require(C30 >= 0, "membrane.law.C30", C30, ">= 0");
  }

  EnergyDensity operator()(double A1, double A2) const { return at_area_ratio(std::exp(A1), A2); }
  /// The same from the area ratio r = J/Jbar = e^{A1} (19), without evaluating A1 (force loops).
  [[gnu::always_inline]] EnergyDensity at_area_ratio(double r, double A2) const {
    const double e = 1 / (r * r);  // e^{-2 A1}
    const double I = 2 * A2 + e - 1;
    const double dW_dI = C10 + 3 * C30 * I * I;
    return {C10 * I + C30 * I * I * I, -2 * e * dW_dI, 2 * dW_dI};
  }
};

}  // namespace immerse
