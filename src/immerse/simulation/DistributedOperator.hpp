#pragma once
// The coupled fluid-membrane step of ImmersedBoundaryOperator (the algorithm of §3) distributed over MPI processes:
// the fluid on slabs of z planes (SlabNavierStokesSolver), each membrane on the process owning it (MembraneOwnership:
// the slab of its centroid). Each process's unknowns are the node positions of the membranes it owns, in ascending
// global index, so the explicit integrators (ForwardEuler, MidpointRK2), which only combine positions and velocities
// node by node, run unchanged on every process, each calling the collective methods below in the same sequence.
//
//   f(X)      membrane forces of the owned membranes    ElasticMembrane::compute_force (the object of the membrane's
//                                                       global index; every process holds all of them)
//             plus the contact forces                    ContactForce on the owned membranes and their neighbours
//   S(X) f    spread into the slab force field          SlabIBCoupler::spread_force
//   χ(X̄)      interior indicator, viscosity contrast     SlabViscosityIndicator::compute (X̄ = (X^n + Xf)/2, the
//                                                       owned membranes' midpoints, as ImmersedBoundaryOperator)
//   u^{n+1}   one step on the slabs                     SlabNavierStokesSolver::step
//   J(X) u    interpolated back to the owned nodes      SlabIBCoupler::interpolate_velocity
//
// Contact. A node's contact force sums its neighbours on other membranes within contact.range d. Each evaluation
// all-gathers the bounding box of every membrane (ContactForce::bounds, from the positions of the evaluation); a
// membrane's positions go to every other process owning a membrane whose box comes within d of it
// (ContactForce::boxes_within_range, the serial broad phase, tested with the lower index first as there), in one
// MPI_Alltoallv. The process then evaluates ContactForce on its own and the received membranes, concatenated in
// ascending global index, with the bins sized for all the nodes of the run (ContactForce::set_search_nodes): the bins
// are the serial ones, a bin lists its nodes in ascending global order, and the nodes left out are of membranes that
// cannot come within d, so every node adds the same terms in the same order as in one process: the contact forces of
// the owned nodes equal the serial ones bitwise (given the same positions).
//
// Migration. commit() stores X^{n+1}, moves the membranes whose centroid changed slab to their new owners
// (MembraneOwnership::migrate) and interpolates U^{n+1} = J(X^{n+1}) u^{n+1} at the nodes each process then owns
// (interpolation equals the serial one bitwise, so this is the serial U^{n+1}); size() may change at every commit.
//
// Results. Membrane and contact forces and interpolation equal the serial ones bitwise for the same positions;
// spreading adds in another order (SlabIBCoupler.hpp), so a run differs from the one-process run by round-off, and is
// bitwise the same in every run with the same number of processes. Applied nodal forces are not distributed.
// correct_positions() replaces the committed positions after an accepted step (the volume correction), as
// ImmersedBoundaryOperator::correct_positions does.
//
// Implicit step. A trial with theta < 1 is driven, as in ImmersedBoundaryOperator, by
// F^{n+1/2} = theta S(Xf) f(Xf) + (1 - theta) S(X^n) f(X^n) (eq. 31), the start force taken over from the last trial
// when that was driven by X^{n+1} (an implicit step's is), else computed when a trial first needs it. The implicit
// schemes (SnesIntegrator) run on it with PETSc MPI vectors whose local part is size(). Every method that evaluates
// or commits is collective; when a membrane fails (a node outside the box, an inverted element) every process throws
// SimulationError (the owner naming the membrane). No global state.
// Verified by: the tests ParallelRun.* (tests/test_parallel_run.cpp, 1 to 4 processes: the quick red-cell channel
// with the midpoint RK2 scheme, with forward Euler, with JFNK, Anderson and L-BFGS, and with contact between cells of
// different processes, against the one-process Simulation within 1e-10, repeated bitwise, with cells changing owner
// on 2 and 4 processes; and with a viscosity contrast λ = 5 and the volume correction).
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "immerse/contact/ContactForce.hpp"
#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/coupling/SlabViscosityIndicator.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/parallel/MembraneOwnership.hpp"
#include "immerse/simulation/StepTimings.hpp"
#include "immerse/timestep/CoupledOperator.hpp"

namespace immerse {

class DistributedOperator final : public CoupledOperator {
 public:
  /// `membranes`: the force objects of all membranes, by global index (kept by pointer); X0 and `reference` their
  /// initial and reference positions (every process passes the same); `fluid_state` this process's slab state
  /// (SlabNavierStokesSolver::scatter); the membranes repel each other and the walls by `contact` (off by default);
  /// viscosity_ratio holds each membrane's λ = μ_in/μ_out (empty: all 1; any λ ≠ 1 needs a fluid solver with
  /// variable viscosity). `fluid` and `coupler` are kept by reference. Collective.
  DistributedOperator(SlabNavierStokesSolver& fluid, SlabIBCoupler& coupler,
                      std::vector<const ElasticMembrane*> membranes, std::span<const std::vector<Vec3>> X0,
                      std::span<const std::vector<Vec3>> reference, FluidState fluid_state,
                      const ContactSettings& contact = {}, std::vector<double> viscosity_ratio = {});
  DistributedOperator(const DistributedOperator&) = delete;  // its ownership refers to the fluid's decomposition
  DistributedOperator& operator=(const DistributedOperator&) = delete;

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
  /// This process's part only: callers that act on the answer collectively agree on it first.
  bool trial_matches(std::span<const double> X) const override;
  void commit(std::span<const double> X, double dt) override;
  std::size_t fluid_solves() const override { return solves_; }

  /// The owned membranes (global index, positions X^n, reference positions).
  const MembraneOwnership& ownership() const { return ownership_; }
  /// This process's slab of the committed fluid state.
  const FluidState& fluid_state() const { return committed_; }
  /// Membranes moved to another process by the commits and corrections so far (the same on every process).
  int migrations() const { return migrations_; }
  /// Wall time of this process in each part of the step so far.
  const StepTimings& timings() const { return timings_; }
  /// The OpenMP threads of this process (membrane forces, contact, the fluid kernels, interpolation): each
  /// evaluation of the residual runs with the count the governor chooses and reports its wall time to it, as in
  /// ImmersedBoundaryOperator. Results do not depend on the count.
  void set_thread_governor(const ThreadGovernor& g) { governor_ = g; }
  const ThreadGovernor& thread_governor() const { return governor_; }
  /// χ of the last trial on this process's slab (empty without a viscosity contrast).
  const Array3& viscosity_indicator() const { return chi_; }
  /// Replaces the committed positions of the owned nodes by X (concatenated as positions()) after an accepted step:
  /// the node velocities become J(X) u^n of the committed fluid, which is not changed, and the membranes whose
  /// centroid changed slab migrate, so size() may change. Collective.
  void correct_positions(std::span<const Vec3> X);

 private:
  static std::span<const double> flat(const std::vector<Vec3>& v) {
    return {reinterpret_cast<const double*>(v.data()), 3 * v.size()};
  }
  /// X_ and offset_ from the ownership's membranes.
  void refresh();
  /// F = f(Xf) at the owned nodes: membrane forces, then the contact forces added. Collective.
  void nodal_forces(std::span<const Vec3> Xf);
  /// The message every process throws once a membrane failed at Xf: `error` of owned membrane `failed` on a process
  /// where one failed (empty elsewhere). Collective.
  std::string failure_report(std::span<const Vec3> Xf, std::size_t failed, const std::string& error) const;
  /// Adds the contact forces of the owned nodes at Xf to F_. Collective.
  void add_contact_forces(std::span<const Vec3> Xf);
  /// Forces at Xf, spreading and the fluid step into trial_ driven by F^{n+1/2} of (Xf, theta). Collective.
  void trial_step(std::span<const double> Xf, double theta, double dt);
  /// Runs one evaluation of the residual with the thread count the governor chooses, and reports its time.
  template <class F>
  void governed(F&& evaluation);
  /// The owned positions replaced by X, membranes migrated and U = J(X) u^n at the nodes owned then; no trial
  /// left. Collective.
  void move_to(std::span<const Vec3> X);
  /// chi_ at the midpoints (X^n + Xf)/2 of the owned membranes (with a viscosity contrast). Collective.
  void update_indicator(std::span<const Vec3> Xf);

  SlabNavierStokesSolver& fluid_;
  SlabIBCoupler& coupler_;
  std::vector<const ElasticMembrane*> membranes_;  ///< all, by global index
  std::vector<double> moduli_;                     ///< K_s of each membrane, by global index (contact)
  ContactSettings contact_;
  std::size_t total_nodes_ = 0;  ///< of all membranes
  MembraneOwnership ownership_;
  std::vector<std::size_t> offset_;  ///< first node of each owned membrane in X_, then the node count
  std::vector<Vec3> X_, U_;          ///< committed positions and node velocities of the owned nodes
  FluidState committed_, trial_;     ///< slab states
  FaceField force_;                  ///< S(Xf) f(Xf) of the last trial (slab)
  FaceField force_start_;            ///< S(X^n) f(X^n), when start_valid_ (slab)
  bool start_valid_ = false;
  FaceField mixed_;                  ///< F^{n+1/2} of the last trial with theta < 1 (slab)
  FaceField mean_;                   ///< (u^n + u^{n+1}) / 2 of trial_mean_velocity (slab)
  std::vector<Vec3> F_;              ///< nodal forces of the owned nodes
  std::vector<std::vector<Vec3>> Fm_;  ///< work: one membrane's forces
  std::vector<double> trial_X_;      ///< the Xf of the last completed trial, when trial_done_
  bool trial_done_ = false;          ///< a flag: a process owning no membrane has an empty trial_X_ too
  std::unique_ptr<SlabViscosityIndicator> indicator_;  ///< with a viscosity contrast
  std::vector<std::vector<Vec3>> Xmid_;              ///< midpoint positions of the owned membranes in a trial
  Array3 chi_;                                       ///< χ of the last trial (slab)
  std::size_t solves_ = 0;
  int migrations_ = 0;
  StepTimings timings_;
  ThreadGovernor governor_;
};

}  // namespace immerse
