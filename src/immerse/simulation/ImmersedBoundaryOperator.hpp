#pragma once
// The coupled fluid-membrane step as the integrators see it (timestep/CoupledOperator.hpp): the algorithm of §3.
//
//   f(X)      membrane forces at the nodes           ElasticMembrane::compute_force  (§2.3, eq. 42 or -dE/dX)
//             plus the contact forces                 ContactForce::compute (membrane-membrane, membrane-wall)
//   S(X) f    spread to the MAC faces                 IBCoupler::spread_force          (eq. 6)
//   χ(X̄)      interior indicator, viscosity contrast  ViscosityIndicator::compute      (X̄ = (X^n + Xf)/2)
//   u^{n+1}   one projection step driven by F^{n+1/2}  NavierStokesSolver::prepare, step (eqs. 9-13)
//   J(X) u    interpolated back to the nodes          IBCoupler::interpolate_velocity  (eq. 14)
//
// with F^{n+1/2} = (1 - theta) S(X^n) f(X^n) + theta S(Xf) f(Xf); S(X^n) f(X^n) is taken over from the last trial
// when that was driven by X^{n+1} (as an implicit step's is), else computed once, when a trial with theta < 1
// first needs it. The committed fluid state is never modified by trial steps; commit() swaps the last trial in, and
// takes its node velocity J(X^{n+1}) u^{n+1} over when that trial was driven and interpolated at X^{n+1}. The part
// of the fluid step that does not depend on the force is prepared once from the committed state for the trials'
// dt, and shared by all the trials with that dt until commit().
// With a viscosity contrast (a membrane's viscosity_ratio λ ≠ 1) every trial evaluates the indicator χ at the
// midpoint of the committed positions and its own, X̄ = (X^n + Xf)/2, and the fluid step takes μ = μ_out (1 + χ):
// the residual g(X) of an implicit step then holds the viscosity of its own midpoint.
// All membranes' nodes are concatenated in one array; errors name the membrane and its local node or element.
// Verified by the tests ImmersedBoundaryOperator.* (thread independence, what trials take over and reuse, failing
// membrane named), Reproducibility/ViscosityContrast.* (a viscosity contrast across thread counts and a restart) and
// the studies oscillating_time_order and oscillating_stability, which step through it.
#include <algorithm>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "immerse/contact/ContactForce.hpp"
#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/ViscosityIndicator.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/simulation/StepTimings.hpp"
#include "immerse/timestep/CoupledOperator.hpp"

namespace immerse {

class ImmersedBoundaryOperator final : public CoupledOperator {
 public:
  /// `membranes` and their initial positions X0 (one array per membrane); the fluid starts from `fluid_state`;
  /// the membranes repel each other and the walls by `contact` (off by default); viscosity_ratio holds each
  /// membrane's λ = μ_in/μ_out (empty: all 1; any λ ≠ 1 needs a fluid solver with variable viscosity).
  ImmersedBoundaryOperator(NavierStokesSolver& fluid, IBCoupler& coupler,
                           std::vector<const ElasticMembrane*> membranes, std::vector<std::vector<Vec3>> X0,
                           FluidState fluid_state, const ContactSettings& contact = {},
                           std::vector<double> viscosity_ratio = {});

  std::size_t size() const override { return 3 * X_.size(); }
  std::span<const double> positions() const override { return flat(X_); }
  std::span<const double> node_velocity() const override { return flat(U_); }
  std::vector<std::size_t> membrane_offsets() const override;
  double length_scale() const override { return fluid_.grid().h(); }
  void trial_velocity(std::span<const double> Xf, double theta, std::span<const double> Xi, double dt,
                      std::span<double> U) override;
  void committed_velocity(std::span<const double> Xi, std::span<double> U) override;
  /// One interpolation, of the mean field (u^n + u^{n+1}) / 2.
  void trial_mean_velocity(std::span<const double> Xf, std::span<const double> Xi, double dt,
                           std::span<double> U) override;
  bool trial_matches(std::span<const double> X) const override { return std::ranges::equal(X, trial_X_); }
  void commit(std::span<const double> X, double dt) override;
  std::size_t fluid_solves() const override { return solves_; }

  const FluidState& fluid_state() const { return committed_; }
  /// Wall time spent so far in each part of the coupled step (since construction, which evaluates the forces once).
  const StepTimings& timings() const { return timings_; }
  /// The policy that sets OpenMP's thread count before each evaluation of the residual (fixed by default).
  void set_thread_governor(const ThreadGovernor& g) { governor_ = g; }
  const ThreadGovernor& thread_governor() const { return governor_; }
  std::size_t num_membranes() const { return membranes_.size(); }
  /// χ of the last trial (empty without a viscosity contrast).
  const Array3& viscosity_indicator() const { return chi_; }
  /// Committed positions of membrane m.
  std::vector<Vec3> membrane_positions(std::size_t m) const;
  /// Committed node velocities of membrane m.
  std::vector<Vec3> membrane_velocities(std::size_t m) const;
  /// Replaces the committed positions of membrane m by X after an accepted step (a correction such as
  /// VolumeCorrection's normal shift): its node velocities become J(X) u^n of the committed fluid, which is not
  /// changed, and the next step's start force S(X^n) f(X^n) is computed at the new positions.
  void correct_positions(std::size_t m, const std::vector<Vec3>& X);
  /// Smallest distance of any node to a wall (infinity without walls).
  double min_wall_distance() const;
  /// External nodal forces (N) on membrane m, added to its elastic force from now on (e.g. optical tweezers,
  /// §4.3). The start-of-step force S(X^n) f(X^n) will be recomputed with them.
  void set_applied_forces(std::size_t m, const std::vector<Vec3>& F);

 private:
  static std::span<const double> flat(const std::vector<Vec3>& v) {
    return {reinterpret_cast<const double*>(v.data()), 3 * v.size()};
  }
  static std::span<const Vec3> nodes(std::span<const double> x) {
    return {reinterpret_cast<const Vec3*>(x.data()), x.size() / 3};
  }
  /// F_ for membrane m at the all-membrane positions X: its elastic force plus the applied force.
  void nodal_force(std::size_t m, std::span<const Vec3> X);
  /// f = S(X) f(X) for all membranes, the contact forces included.
  void membrane_force_density(std::span<const Vec3> X, FaceField& f);
  /// The fluid step of a trial: trial_ = the step from committed_ driven by F^{n+1/2} of (Xf, theta).
  /// Returns the seconds spent on work that not every evaluation does (the start force, the fluid preparation),
  /// which the thread governor leaves out of its comparison.
  double trial_step(std::span<const double> Xf, double theta, double dt);
  /// χ_ at the midpoint (X^n + Xf)/2 (with a viscosity contrast).
  void update_indicator(std::span<const Vec3> Xf);
  /// Runs one evaluation of the residual with the thread count the governor chooses, and reports its time.
  template <class F>
  void governed(F&& evaluation);

  NavierStokesSolver& fluid_;
  IBCoupler& coupler_;
  std::vector<const ElasticMembrane*> membranes_;
  std::vector<std::size_t> offset_;  ///< first node of membrane m in the concatenated arrays
  std::vector<Vec3> X_, U_;          ///< committed positions and node velocities
  FluidState committed_, trial_;
  /// The force-independent part of a fluid step from committed_ (NavierStokesSolver::prepare), reused by the
  /// trials while prepared_for(committed_, dt): the key (address, step counter and time of the state, dt) changes
  /// with every commit() (the committed step advances), with a new dt (a retried step) and in a copied or moved
  /// operator; cheaper than comparing the fields, which would read the whole state at every trial.
  PreparedStep prepared_;
  FaceField force_start_;       ///< S(X^n) f(X^n), when start_valid_
  bool start_valid_ = true;
  FaceField force_;             ///< S(Xf) f(Xf) of the last trial
  FaceField mixed_;             ///< F^{n+1/2} of the last trial (allocated by the first trial with theta < 1)
  FaceField mean_;              ///< (u^n + u^{n+1}) / 2 of trial_mean_velocity (allocated by its first call)
  std::vector<double> trial_X_;  ///< the Xf of the last completed trial (empty when none can be reused at commit)
  std::vector<Vec3> trial_U_;    ///< J(Xi) u of the last trial, when trial_U_valid_ (it was interpolated at Xi = Xf)
  bool trial_U_valid_ = false;
  std::vector<Vec3> F_;                                 ///< nodal forces, all membranes
  std::vector<Vec3> applied_;                           ///< external nodal forces, all membranes
  std::optional<ContactForce> contact_;                 ///< when its range is positive
  std::vector<Vec3> contact_F_;                         ///< contact forces, all membranes
  std::vector<std::vector<Vec3>> Fm_;                   ///< per-membrane forces of compute_force
  std::vector<double> ratio_;                           ///< λ of each membrane, with a viscosity contrast
  std::unique_ptr<ViscosityIndicator> indicator_;       ///< with a viscosity contrast
  std::vector<std::vector<Vec3>> Xmid_;                 ///< per-membrane midpoint positions of the trial
  Array3 chi_;                                          ///< χ of the last trial
  std::size_t solves_ = 0;
  StepTimings timings_;
  ThreadGovernor governor_;
};

static_assert(sizeof(Vec3) == 3 * sizeof(double), "positions are viewed as flat arrays of doubles");

}  // namespace immerse
