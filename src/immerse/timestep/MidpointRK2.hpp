#pragma once
// Explicit second-order Runge-Kutta (midpoint) membrane update in the spirit of Peskin's review
// (Acta Numerica 2002, ref. [37] of the paper), the reference scheme of §4.4:
//   X~ = X^n + (dt/2) U^n                                  (predicted midpoint positions)
//   F^{n+1/2} = S(X~) f(X~),  one Crank-Nicolson fluid step  u^n -> u^{n+1}
//   X^{n+1} = X^n + dt J(X~) (u^n + u^{n+1}) / 2            (midpoint velocity at midpoint positions)
// One fluid solve per step; second order in time for X and u, explicit (stiffness-limited) in the membrane force.
// [37] moves the nodes with u^{n+1/2} from a backward-Euler half step, a second fluid solve. The mean m* = (u* + u^n)/2
// of the Crank-Nicolson step (9) solves that half step's equation, rho (m* - u^n)/(dt/2) = E + mu lap_h m* + F with
// the same explicit terms E, and since D u^n = 0 its projection takes the same phi: (u^n + u^{n+1})/2 is [37]'s
// u^{n+1/2} apart from the explicit advection and pressure terms, at half the fluid work. The mean is interpolated
// once (CoupledOperator::trial_mean_velocity): two interpolations per step, J(X^n) u^n and this one.
// Verified by the tests Integrators.MidpointRK2IsSecondOrderAndEulerFirst and
// ImmersedBoundaryOperator.TrialMeanVelocityIsTheMeanOfTheCommittedAndTrialVelocities.
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class MidpointRK2 final : public MembraneIntegrator {
 public:
  SolverStats step(CoupledOperator& op, double dt) override;
  std::string name() const override { return "rk2"; }

 private:
  std::vector<double> Xm_, Um_, X_;
};

}  // namespace immerse
