#pragma once
// The seam between the membrane time integrators (paper §2.4, §3) and the fluid, the membranes and their coupling.
//
// Unknowns are the node positions of all membranes, flattened: X = (x0, y0, z0, x1, ...).
// Notation: S(X) spreading (eq. 6), J(X) interpolation (eq. 14), f(X) membrane force (§2.3),
// u^n the committed fluid velocity, U^n = J(X^n) u^n the committed node velocity.
// The integrators see nothing of grids: only positions, node velocities, and one fluid step as a function.
#include <cstddef>
#include <span>
#include <vector>

namespace immerse {

class CoupledOperator {
 public:
  virtual ~CoupledOperator() = default;

  /// Number of scalar unknowns (3 per node).
  virtual std::size_t size() const = 0;
  /// Committed positions X^n.
  virtual std::span<const double> positions() const = 0;
  /// Committed node velocity U^n = J(X^n) u^n.
  virtual std::span<const double> node_velocity() const = 0;
  /// Where each membrane's unknowns begin in X, then size(): membrane m holds [offsets[m], offsets[m+1]).
  virtual std::vector<std::size_t> membrane_offsets() const { return {0, size()}; }
  /// Length scale of the problem (e.g. the grid spacing); the solvers measure positions in it.
  virtual double length_scale() const = 0;

  /// One fluid step of length dt from the committed state, driven by the membrane force density
  ///   F^{n+1/2} = (1 - theta) S(X^n) f(X^n) + theta S(X_force) f(X_force),
  /// returning U = J(X_interp) u^{n+1}: the force is taken at X_force, the velocity interpolated at X_interp (every
  /// integrator here passes the same positions for both). Pure in the committed state: the new fluid state is kept as
  /// the trial. Throws SimulationError when a node leaves the domain or an element inverts.
  virtual void trial_velocity(std::span<const double> X_force, double theta, std::span<const double> X_interp,
                              double dt, std::span<double> U) = 0;
  /// U = J(X_interp) u^n for the committed fluid velocity.
  virtual void committed_velocity(std::span<const double> X_interp, std::span<double> U) = 0;
  /// The midpoint rule's velocity: the fluid step of trial_velocity(X_force, 1, X_interp, dt, ·), returning the step's
  /// mean node velocity U = J(X_interp) (u^n + u^{n+1}) / 2. Here two interpolations; an operator may interpolate the
  /// mean field once (J is linear in u).
  virtual void trial_mean_velocity(std::span<const double> X_force, std::span<const double> X_interp, double dt,
                                   std::span<double> U) {
    std::vector<double> Un(U.size());
    trial_velocity(X_force, 1.0, X_interp, dt, U);
    committed_velocity(X_interp, Un);
    for (std::size_t i = 0; i < U.size(); ++i) U[i] = 0.5 * (Un[i] + U[i]);
  }
  /// True when the last trial_velocity call completed with X_force = X exactly: its trial state is then the one the
  /// positions X drive, ready to be committed.
  virtual bool trial_matches(std::span<const double> X) const = 0;
  /// Accepts the step: X^{n+1} = X, the fluid state becomes the trial of the last trial_velocity call, and
  /// U^{n+1} = J(X^{n+1}) u^{n+1}.
  virtual void commit(std::span<const double> X, double dt) = 0;

  /// Fluid steps performed so far (the unit of cost, notes: "fluid solves per step").
  virtual std::size_t fluid_solves() const = 0;
};

}  // namespace immerse
