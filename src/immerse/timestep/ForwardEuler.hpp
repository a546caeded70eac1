#pragma once
// Explicit forward Euler, eq. (28), exactly as the four steps of §2.4.1:
//   X^{n+1} = X^n + dt U^n,  F^{n+1/2} = S(X^{n+1}) f(X^{n+1}),  fluid step,  U^{n+1} = J(X^{n+1}) u^{n+1}.
// One fluid solve per step; stable only for dt below the membrane's stiffness limit.
// Verified by: the study oscillating_stability and the tests Integrators.StiffSpringBreaksEulerButNotJfnk,
// Integrators.MidpointRK2IsSecondOrderAndEulerFirst and RunUnstable.ExplicitSchemePastItsLimitStopsWithStatus3.
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class ForwardEuler final : public MembraneIntegrator {
 public:
  SolverStats step(CoupledOperator& op, double dt) override;
  std::string name() const override { return "euler"; }

 private:
  std::vector<double> X_, U_;
};

}  // namespace immerse
