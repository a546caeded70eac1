#pragma once
// Explicit second-order Runge-Kutta (midpoint) membrane update in the spirit of Peskin's review
// (Acta Numerica 2002, ref. [37] of the paper), the reference scheme of §4.4:
//   X~ = X^n + (dt/2) U^n                                  (predicted midpoint positions)
//   F^{n+1/2} = S(X~) f(X~),  one Crank-Nicolson fluid step  u^n -> u^{n+1}
//   X^{n+1} = X^n + dt J(X~) (u^n + u^{n+1}) / 2            (midpoint velocity at midpoint positions)
// One fluid solve per step; second order in time for X and u, explicit (stiffness-limited) in the membrane force.
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class MidpointRK2 final : public MembraneIntegrator {
 public:
  StepStats step(CoupledOperator& op, double dt) override;
  std::string name() const override { return "rk2"; }

 private:
  std::vector<double> Xm_, U0_, U1_, X_;
};

}  // namespace immerse
