#include "immerse/timestep/ForwardEuler.hpp"

namespace immerse {

SolverStats ForwardEuler::step(CoupledOperator& op, double dt) {
  const std::size_t n = op.size(), solves0 = op.fluid_solves();
  const auto Xn = op.positions();
  const auto Un = op.node_velocity();
  X_.resize(n);
  U_.resize(n);
  for (std::size_t i = 0; i < n; ++i) X_[i] = Xn[i] + dt * Un[i];  // eq. (28)
  op.trial_velocity(X_, 1.0, X_, dt, U_);
  remember(op, dt);
  op.commit(X_, dt);
  SolverStats s;
  s.fluid_solves = op.fluid_solves() - solves0;
  return s;
}

}  // namespace immerse
