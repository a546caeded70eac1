#pragma once
// Quasi-Newton solution of g(X) = 0 (eqs. 30-31) with the dense inverse-Jacobian update of eq. (35), as printed,
// with gamma_k = theta_k = 1 (BFGS):
//
//   X^(k+1) = X^(k) - H_k g^(k),   p_k = X^(k+1) - X^(k),   q_k = g^(k+1) - g^(k),
//   H_{k+1} = H_k + (1 + q^T H q / p^T q) p p^T / p^T q - (p q^T H + H q p^T) / p^T q,
//
// starting each step from H_0 = I (J = I - (dt/2) u' of eq. (32) is close to I) and the X^(0) of the other
// implicit schemes (MembraneIntegrator::initial_guess: 2X^n - X^{n-1}, corrected by GuessErrorPredictor by default).
// H is n x n (n = 3 x nodes): §2.4.2 explains why this cannot run on the 3D meshes of §4; use "lbfgs" there.
// Verified by: the study quasi_newton_agreement (reaches JFNK's X^{n+1}, ≤ 1e-9 relative) and the tests
// Integrators.QuasiNewtonVariantsAreSecondOrder and Integrators.QuasiNewtonAndAndersonAndJfnkReachTheSameStep.
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class DenseBfgs final : public MembraneIntegrator {
 public:
  /// Largest number of unknowns accepted (the n x n matrix must fit comfortably in memory).
  static constexpr std::size_t max_unknowns = 12000;
  explicit DenseBfgs(const SolverSettings& settings);
  SolverStats step(CoupledOperator& op, double dt) override;
  std::string name() const override { return "bfgs"; }

 private:
  SolverSettings settings_;
  std::vector<double> H_, X_, g_, Xn_, gn_, p_, q_, Hq_;
};

}  // namespace immerse
