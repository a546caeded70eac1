#pragma once
// Neo-Hookean thin membrane, eq. (22):  W = (Es/6) (2 A2 + e^{-2 A1} - 1).
// Small-strain surface shear modulus Gs = Es/3, area modulus Ks = Es. Isotropic stretch lambda:
// tau = (Es/3) (1 - lambda^-6).
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/EnergyDensity.hpp"

namespace immerse {

struct NeoHookean {
  double Es;  ///< surface elastic modulus E h, N/m

  explicit NeoHookean(double Es_) : Es(Es_) { require(Es > 0, "membrane.law.Es", Es, "> 0"); }

  [[gnu::always_inline]] EnergyDensity operator()(double A1, double A2) const {
    const double e = std::exp(-2 * A1);
    return {Es / 6 * (2 * A2 + e - 1), -Es / 3 * e, Es / 3};
  }
};

}  // namespace immerse
