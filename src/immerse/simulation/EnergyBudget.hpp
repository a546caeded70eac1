#pragma once
// The energy budget of a run (docs/energy-budget.md). With spreading adjoint to interpolation and membrane forces
// −∂E/∂X, the semi-discrete system satisfies
//
//   d/dt (E_kinetic + Σ_m E_m) = −dissipation + P_walls + P_body
//
// (Peskin 2002, Acta Numerica 11:479; Newren, Fogelson, Guy & Kirby 2007, J. Comput. Phys. 222:702). The budget
// integrates the right-hand side over the run by the trapezoidal rule, step by step, from the fluid measures at the
// start and after each accepted step (FluidEnergy.hpp), and gives the residual
//
//   E_total(t) − E_total(t0) + ∫ dissipation dt − ∫ (P_walls + P_body) dt,
//
// which the time discretization, the advection term, forces that are not −∂E/∂X (the contour method, contact,
// applied forces) and the volume correction make differ from zero. Its state goes into the checkpoints, so that a
// restarted run continues the same integrals.
// Verified by: the tests EnergyBudget.* and FluidEnergy.* (tests/test_energy_budget.cpp).
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FluidEnergy.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"

namespace immerse {

/// The energies of membrane m at positions X (SimulationError if an element is inverted).
MembraneEnergy membrane_energy(const ElasticMembrane& m, std::span<const Vec3> X);

/// E_total: the kinetic energy of the fluid plus every membrane's energies, added in membrane order.
double total_energy(double kinetic, std::span<const MembraneEnergy> membranes);

class EnergyBudget {
 public:
  /// Starts the integrals at a state of total energy `total` and fluid measures `fluid`.
  void start(double total, const FluidEnergy& fluid);
  /// After an accepted step of size dt that reached a state of fluid measures `fluid`.
  void advance(double dt, const FluidEnergy& fluid);
  /// Adds `extra` (W) to the last state's body power before the step from it is advanced: with fluid.flow_rate each
  /// step adds its own force, and the trapezoidal rule takes the power at both ends with the force of the step.
  void add_body_power(double extra) { fluid_.body += extra; }

  /// The fluid measures at the last state.
  const FluidEnergy& fluid() const { return fluid_; }
  double initial_total() const { return initial_; }
  /// ∫ dissipation dt, ∫ P_walls dt, ∫ P_body dt since the start (J).
  double dissipated() const { return dissipated_; }
  double walls_work() const { return walls_work_; }
  double body_work() const { return body_work_; }
  /// E_total − E_total(t0) + ∫ dissipation dt − ∫ (P_walls + P_body) dt for the current total energy.
  double residual(double total) const { return (total - initial_) + (dissipated_ - walls_work_ - body_work_); }

  /// The checkpoint entries of the budget (name, value).
  std::vector<std::pair<std::string, double>> entries() const;
  /// Whether `ck` holds a budget (checkpoints written before the budget existed do not).
  static bool saved_in(const io::Checkpoint& ck);
  /// Continues the budget of `ck` (InputError on an entry that is not finite); false, and nothing changed, when it
  /// holds none.
  bool restore(const io::Checkpoint& ck);

 private:
  FluidEnergy fluid_;
  double initial_ = 0, dissipated_ = 0, walls_work_ = 0, body_work_ = 0;
};

}  // namespace immerse
