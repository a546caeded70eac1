#pragma once
// Value of a surface strain-energy function W(A1, A2) (N/m) and its partial derivatives, the inputs of the
// tension law (18): tau = e^{-A1} (dW/dA1 P + dW/dA2 B).
//   A1 = ln(lambda1 lambda2)                      (19)  area dilatation
//   A2 = (lambda1^2 + lambda2^2)/2 - 1            (20)
// Verified by the tests MembraneMaterial.* (dW/dA1 and dW/dA2 of every law against central differences of W).
namespace immerse {

struct EnergyDensity {
  double W = 0;       ///< strain energy per unit reference area, N/m
  double dW_dA1 = 0;  ///< N/m
  double dW_dA2 = 0;  ///< N/m
};

}  // namespace immerse
