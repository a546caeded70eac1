#pragma once
// The pluggable in-plane constitutive law of the membrane (paper §2.3.1, eqs. 22-24), optionally with the local
// area dilation energy of AreaDilation.hpp.
#include <string>
#include <type_traits>
#include <variant>

#include "immerse/membrane/AreaDilation.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/Skalak.hpp"
#include "immerse/membrane/Yeoh.hpp"

namespace immerse {

using MaterialLaw = std::variant<NeoHookean, Yeoh, Skalak, WithAreaDilation<NeoHookean>, WithAreaDilation<Yeoh>,
                                 WithAreaDilation<Skalak>>;

/// `law` with the area dilation energy of modulus K_D (N/m) added; `law` itself when K_D = 0.
inline MaterialLaw with_area_dilation(const MaterialLaw& law, double K_D) {
  if (K_D == 0) return law;
  return std::visit(
      [&](const auto& w) -> MaterialLaw {
        using L = std::decay_t<decltype(w)>;
        if constexpr (requires { w.law; })
          return WithAreaDilation<decltype(w.law)>(w.law, w.K_D + K_D);
        else
          return WithAreaDilation<L>(w, K_D);
      },
      law);
}

/// The in-plane law without the area dilation energy.
inline MaterialLaw without_area_dilation(const MaterialLaw& law) {
  return std::visit(
      [](const auto& w) -> MaterialLaw {
        if constexpr (requires { w.law; })
          return w.law;
        else
          return w;
      },
      law);
}

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
