#pragma once
// Skalak red-blood-cell membrane, eq. (24):
//   W = (C11/4) (2 A2 (A2 + 1) + 1 - e^{2 A1}) + (C21/8) (e^{2 A1} - 1)^2,   typically C11 << C21.
// In the usual notation C11 = 2 Gs (shear modulus) and C21 = 2 C Gs (area dilatation).
// Isotropic stretch lambda: tau = (C11/2) (lambda^2 - 1) + (C21/2) lambda^2 (lambda^4 - 1).
// Verified by the tests MembraneMaterial.* (derivatives, isotropic tension, small-strain moduli) and the studies
// membrane_inflation (tensions against the closed forms) and membrane_energy_gradient.
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/EnergyDensity.hpp"

namespace immerse {

struct Skalak {
  double C11;  ///< N/m
  double C21;  ///< N/m

  Skalak(double C11_, double C21_) : C11(C11_), C21(C21_) {
    require(C11 > 0, "membrane.law.C11", C11, "> 0");
    require(C21 >= 0, "membrane.law.C21", C21, ">= 0");
  }

  EnergyDensity operator()(double A1, double A2) const { return at_area_ratio(std::exp(A1), A2); }
  /// The same from the area ratio r = J/Jbar = e^{A1} (19), without evaluating A1 (force loops).
  [[gnu::always_inline]] EnergyDensity at_area_ratio(double r, double A2) const {
    const double e = r * r;  // e^{2 A1}
    return {C11 / 4 * (2 * A2 * (A2 + 1) + 1 - e) + C21 / 8 * (e - 1) * (e - 1),
            -C11 / 2 * e + C21 / 2 * (e - 1) * e, C11 / 2 * (2 * A2 + 1)};
  }
};

}  // namespace immerse
