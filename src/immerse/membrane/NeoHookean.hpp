#pragma once
// Neo-Hookean thin membrane, eq. (22):  W = (Es/6) (2 A2 + e^{-2 A1} - 1).
// Small-strain surface shear modulus Gs = Es/3, area modulus Ks = Es. Isotropic stretch lambda:
// tau = (Es/3) (1 - lambda^-6).
// Verified by the tests MembraneMaterial.* (derivatives, isotropic tension, small-strain moduli, Laplace peak) and
// the studies membrane_inflation (tensions against the closed forms) and membrane_energy_gradient.
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/EnergyDensity.hpp"

namespace immerse {

struct NeoHookean {
  double Es;  ///< surface elastic modulus E h, N/m

  explicit NeoHookean(double Es_) : Es(Es_) { require(Es > 0, "membrane.law.Es", Es, "> 0"); }

  EnergyDensity operator()(double A1, double A2) const { return at_area_ratio(std::exp(A1), A2); }
  /// The same from the area ratio r = J/Jbar = e^{A1} (19), without evaluating A1 (force loops).
  [[gnu::always_inline]] EnergyDensity at_area_ratio(double r, double A2) const {
    const double e = 1 / (r * r);  // e^{-2 A1}
    return {Es / 6 * (2 * A2 + e - 1), -Es / 3 * e, Es / 3};
  }
};

}  // namespace immerse
