#pragma once
// One run distributed over the MPI processes of a communicator: the grid cut into slabs of z planes
// (SlabNavierStokesSolver, SlabIBCoupler), each membrane advanced by the process owning it (DistributedOperator,
// MembraneOwnership), built from the same resolved configuration as Simulation with the same code (run_grid,
// run_fluid_params, run_contact_settings, run_initial_fluid_state of ConfigSetup.hpp; the membranes, packing included,
// of build_membrane_set): every process builds all membranes (meshes, reference positions, force objects) and keeps
// the ones it owns as its unknowns.
//
// Time stepping: time.scheme = "euler" (ForwardEuler), "rk2" (MidpointRK2), or the implicit "jfnk", "anderson" and
// "lbfgs" (SnesIntegrator on PETSc MPI vectors over the communicator, make_integrator's overload with one), the same
// integrator classes as the one-process run, stepped by AdaptiveStepper as Simulation does (time.dt, halved on a
// failed nonlinear solve down to time.dt_min, the last step shortened to end at time.end; an explicit scheme never
// rejects a step). The integrator's history (X^{n-1} and the guess errors of GuessErrorPredictor, per membrane) moves
// with the membranes when they change owner (MembraneOwnership::follow), so every membrane's initial guess is the
// one-process run's. A viscosity contrast (viscosity_ratio ≠ 1) runs as in Simulation: the variable-viscosity fluid
// step on the slabs with χ at each trial's midpoint (DistributedOperator). With volume_correction = "normal_shift"
// each owner shifts its membranes back to their initial volume after every accepted step (normal_shift of
// VolumeCorrection.hpp), then the node velocities are J(X) u^n at the shifted positions, as Simulation does. The
// result equals Simulation's to round-off (the spreading sums, see DistributedOperator.hpp, and the order of the sums
// in the solvers' norms) and is bitwise the same in every run with the same number of processes.
//
// Refused with InputError: the dense "bfgs" (its matrix spans all unknowns) and applied nodal forces (rbc_stretch).
// `immerse run` drives it, as Simulation, through SimulationInterface; checkpoints and frames are written by all
// processes together, each its own planes and membranes, in the one-process run's layouts.
// Construction and advance() are collective over the communicator. No global state.
// Verified by: the tests ParallelRun.* (tests/test_parallel_run.cpp, 1 to 4 processes: the quick red-cell channel
// with explicit and implicit schemes against the one-process Simulation within 1e-10, repeated bitwise, the same
// iteration counts, also with λ = 5 cells and the volume correction; the refusal); restore() by RunMpi.*
// (tests/test_run_mpi.cpp: a checkpoint of 2 processes continued on 3).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/simulation/DistributedOperator.hpp"
#include "immerse/simulation/EnergyBudget.hpp"
#include "immerse/simulation/MembraneSet.hpp"
#include "immerse/simulation/SimulationInterface.hpp"
#include "immerse/simulation/StepRecord.hpp"
#include "immerse/timestep/AdaptiveStepper.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class DistributedSimulation final : public SimulationInterface {
 public:
  /// Builds everything from `config` (already through apply_scenario) over the processes of `comm`. InputError on
  /// inconsistent input (as Simulation) and on what is not distributed yet (above). `stop_requested`, when given, is
  /// asked while [packing] places the cells, and StopRequested thrown on every process when it returns true on any.
  /// Collective.
  DistributedSimulation(const io::Config& config, Communicator comm, const StopQuery& stop_requested = {});

  /// Advances one accepted step, as Simulation::advance (energy budget included): an implicit step whose solve fails
  /// is halved and retried (AdaptiveStepper; each rejection reported through `log`, on every process; then
  /// `stop_requested` asked and agreed). SimulationError on every process when the run becomes unstable (a node not
  /// finite or faster than time.max_speed, a membrane failing) or the halved step would fall below time.dt_min
  /// (naming step, time and why). Collective.
  StepRecord advance(const Log& log = {}, const StopQuery& stop_requested = {}) override;
  bool finished() const override;

  long step() const override { return step_; }
  double time() const override { return op_->fluid_state().time; }
  const Grid& grid() const override { return grid_; }
  const Communicator& communicator() const override { return fluid_.decomposition().communicator(); }
  const DistributedOperator& op() const { return *op_; }
  std::size_t num_membranes() const override { return membranes_.membranes.size(); }
  const Mesh& mesh(std::size_t m) const override { return membranes_.meshes[m]; }
  const ElasticMembrane& membrane(std::size_t m) const override { return *membranes_.membranes[m]; }
  const std::string& packing_summary() const override { return membranes_.packing_summary; }
  /// "distributed over P MPI processes: slabs of B z planes of N".
  std::string decomposition_summary() const override;
  /// Membranes moved between processes so far.
  int migrations() const override { return op_->migrations(); }

  /// The positions of all membranes in global order, on every process. Collective.
  std::vector<std::vector<Vec3>> gather_positions() const { return op_->ownership().gather_positions(); }
  std::vector<std::vector<Vec3>> positions() const override { return gather_positions(); }
  /// The whole-grid fluid state, on every process. Collective.
  FluidState gather_fluid_state() const { return fluid_.gather(op_->fluid_state()); }

  /// What output and checkpoints read: the resolved configuration, the slab fluid solver (its decomposition), the
  /// membranes of the run (meshes, force objects, reference positions; all of them on every process) and the
  /// integrator (its history, of the owned nodes).
  const io::Config& config() const override { return config_; }
  const SlabNavierStokesSolver& fluid() const { return fluid_; }
  const MembraneSet& membranes() const { return membranes_; }
  const MembraneIntegrator& integrator() const { return *integrator_; }
  /// The step control (the current step and the accepted steps since it was last changed), saved in checkpoints.
  const AdaptiveStepper& stepper() const { return stepper_; }
  /// The energy budget, as Simulation's, the same on every process (its entries go into checkpoints).
  const EnergyBudget& energy_budget() const override { return budget_; }
  /// The fluid measures of the committed state: each process sums its own planes, and the plane sums of all are
  /// added in plane order, so that they equal one process's to round-off of the fields. Collective.
  FluidEnergy fluid_energy() const;
  /// The energies of every membrane at its committed positions, from the processes owning them, on every process.
  /// SimulationError on every process if a membrane's cannot be evaluated. Collective.
  std::vector<MembraneEnergy> membrane_energies() const override;

  /// Continues from a checkpoint of the same configuration written by any number of processes (or by Simulation):
  /// every process passes the whole checkpoint; the fluid is cut into this run's slabs and the membranes are owned
  /// by the processes holding their centroids. The integrator history (previous positions and guess errors, per node
  /// in global membrane order) is taken for the owned nodes, and the energy budget as Simulation::restore does.
  /// InputError as Simulation::restore. Collective.
  void restore(const io::Checkpoint& ck) override;
  /// Refused (InputError): applied nodal forces (rbc_stretch) are not distributed.
  void set_applied_forces(std::size_t m, const std::vector<Vec3>& F) override;

  double min_wall_distance() const override;
  /// Each process sums its planes; the sums are added in rank order.
  double mean_velocity(int d) const override;
  const FluidParams& fluid_params() const override { return fluid_.params(); }
  const FluidState& committed_fluid() const override { return op_->fluid_state(); }
  /// From the slab holding the cell plane next to the wall.
  double wall_shear_stress(bool upper, double mu, double wall_velocity_x) const override;
  StepTimings timings() const override { return op_->timings(); }
  std::string thread_policy() const override;
  std::string thread_summary() const override;
  /// The entries of Simulation::checkpoint(), each process giving its planes and its membranes
  /// (ParallelCheckpoint); `extra` may add integers, doubles and strings only.
  void write_checkpoint(const std::filesystem::path& file, const Attributes& attributes,
                        const std::function<void(io::Checkpoint&)>& extra) const override;
  /// The frame file of XdmfWriter's layout written together (parallel HDF5), each process its membranes' nodes and
  /// triangles and its z planes of the fluid.
  void write_frame(io::XdmfWriter* series, const std::filesystem::path& dir, int frame, const Attributes& attributes,
                   bool fluid_fields) const override;

 private:
  void check_stability() const;
  /// The volume correction of the owned membranes after an accepted step. Collective.
  void correct_volumes();
  /// After a migration: the integrator's history of the membranes (X^{n-1}, the guess errors) moved along, so that
  /// each membrane's initial guess is the one-process run's. Collective.
  void follow_history();
  /// Starts the energy budget at the committed state (every membrane's energy from its owner). Collective.
  void start_budget();

  io::Config config_;
  double end_time_, max_speed_;
  Grid grid_;
  ThreadGovernor threads_;  ///< this process's OpenMP threads (its CPUs: the launcher's binding, the cgroup quota)
  SlabNavierStokesSolver fluid_;
  SlabIBCoupler coupler_;
  MembraneSet membranes_;
  std::unique_ptr<DistributedOperator> op_;
  std::unique_ptr<MembraneIntegrator> integrator_;
  AdaptiveStepper stepper_;
  EnergyBudget budget_;
  long step_ = 0;
};

}  // namespace immerse
