#pragma once
// Local area dilation energy added to any in-plane law (W of eqs. 22-24):
//   W_D = (K_D / 2) A1^2 = (K_D / 2) (ln J)^2,      J = e^{A1} (19) the local area ratio,
//   dW_D/dA1 = K_D A1,  isotropic tension from (18): tau_D = K_D ln J / J.
// It adds K_D to the small-strain area modulus and leaves the shear response alone. Unlike the area term of
// Skalak's law (24), whose compressive tension peaks at J = 1/sqrt(3) and softens below, tau_D falls without bound
// as J -> 0 (d tau_D / dJ = K_D (1 - ln J) / J^2 > 0 for J < e): a compressed patch can never collapse at a bounded
// energy. Red-cell membranes are nearly area-incompressible (area modulus ~0.5 N/m against a shear modulus of a few
// uN/m; Evans & Waugh 1977, Biophys. J. 20:307); models hold it locally (Fedosov, Caswell & Karniadakis 2010,
// Biophys. J. 98:2215) or with a large Skalak C.
// Verified by the tests MembraneMaterial.* (derivatives, isotropic tension, small-strain moduli of every law with
// the term) and AreaDilation.*.
#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/EnergyDensity.hpp"

namespace immerse {

/// A law of NeoHookean, Yeoh, Skalak with the area dilation energy W_D added.
template <class Law>
struct WithAreaDilation {
  Law law;
  double K_D;  ///< N/m

  WithAreaDilation(Law law_, double K_D_) : law(law_), K_D(K_D_) {
    require(K_D > 0 && std::isfinite(K_D), "membrane.dilation_modulus", K_D, "> 0");
  }

  EnergyDensity operator()(double A1, double A2) const { return add(law(A1, A2), A1); }
  [[gnu::always_inline]] EnergyDensity at_area_ratio(double r, double A2) const {
    return add(law.at_area_ratio(r, A2), std::log(r));
  }

 private:
  [[gnu::always_inline]] EnergyDensity add(EnergyDensity d, double A1) const {
    d.W += 0.5 * K_D * A1 * A1;
    d.dW_dA1 += K_D * A1;
    return d;
  }
};

}  // namespace immerse
