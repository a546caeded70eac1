#pragma once
// The pluggable in-plane constitutive law of the membrane (paper §2.3.1, eqs. 22-24).
#include <string>
#include <variant>

#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/Skalak.hpp"
#include "immerse/membrane/Yeoh.hpp"

namespace immerse {

using MaterialLaw = std::variant<NeoHookean, Yeoh, Skalak>;

/// W, dW/dA1, dW/dA2 of any law (convenience; hot loops visit the law once and call it directly).
inline EnergyDensity energy_density(const MaterialLaw& law, double A1, double A2) {
  return std::visit([&](const auto& w) { return w(A1, A2); }, law);
}

/// Isotropic tension tau(lambda) for equal principal stretches, from (18): tau = lambda^-2 (W1 + W2 lambda^2).
inline double isotropic_tension(const MaterialLaw& law, double lambda) {
  const EnergyDensity d = energy_density(law, 2 * std::log(lambda), lambda * lambda - 1);
  return (d.dW_dA1 + d.dW_dA2 * lambda * lambda) / (lambda * lambda);
}

}  // namespace immerse
