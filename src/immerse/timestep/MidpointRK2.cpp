#include "immerse/timestep/MidpointRK2.hpp"

namespace immerse {

SolverStats MidpointRK2::step(CoupledOperator& op, double dt) {
  const std::size_t n = op.size(), solves0 = op.fluid_solves();
  const auto Xn = op.positions();
  const auto Un = op.node_velocity();
  Xm_.resize(n);
  Um_.resize(n);
  X_.resize(n);
  for (std::size_t i = 0; i < n; ++i) Xm_[i] = Xn[i] + 0.5 * dt * Un[i];
  op.trial_mean_velocity(Xm_, Xm_, dt, Um_);
  for (std::size_t i = 0; i < n; ++i) X_[i] = Xn[i] + dt * Um_[i];
  remember(op, dt);
  op.commit(X_, dt);
  SolverStats s;
  s.fluid_solves = op.fluid_solves() - solves0;
  return s;
}

}  // namespace immerse
