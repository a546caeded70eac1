#pragma once
// One run distributed over the MPI processes of a communicator, with an explicit scheme: the grid cut into slabs of
// z planes (SlabNavierStokesSolver, SlabIBCoupler), each membrane advanced by the process owning it
// (DistributedOperator, MembraneOwnership), built from the same resolved configuration as Simulation with the same
// code (run_grid, run_fluid_params, run_contact_settings, run_initial_fluid_state of RunSetup.hpp; the membranes,
// packing included, of build_membrane_set): every process builds all membranes (meshes, reference positions, force
// objects) and keeps the ones it owns as its unknowns.
//
// Time stepping: time.scheme = "euler" (ForwardEuler) or "rk2" (MidpointRK2), the same integrator objects as the
// one-process run, with the constant step time.dt (the last one shortened to end at time.end, as AdaptiveStepper
// does; an explicit scheme never rejects a step). The result equals Simulation's to round-off (the spreading sums,
// see DistributedOperator.hpp) and is bitwise the same in every run with the same number of processes.
//
// Refused with InputError, as not distributed yet: the implicit schemes (JFNK, Anderson, L-BFGS and BFGS need their
// vectors distributed, PETSc parallel vectors), a membrane with viscosity_ratio ≠ 1 (the variable-viscosity fluid
// step) and volume_correction = "normal_shift". Output and checkpoints are written by the caller (`immerse run` under
// mpirun: app/DistributedRun.hpp) from the accessors below; restore() continues from a checkpoint.
// Construction and advance() are collective over the communicator. No global state.
// Verified by: the tests ParallelRun.* (tests/test_parallel_run.cpp, 1 to 4 processes: the quick red-cell channel
// against the one-process Simulation within 1e-10, repeated bitwise, the refusals); restore() by RunMpi.*
// (tests/test_run_mpi.cpp: a checkpoint of 2 processes continued on 3).
#include <memory>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/SlabNavierStokesSolver.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/simulation/DistributedOperator.hpp"
#include "immerse/simulation/MembraneSet.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class DistributedSimulation {
 public:
  /// Builds everything from `config` (already through apply_scenario) over the processes of `comm`. InputError on
  /// inconsistent input (as Simulation) and on what is not distributed yet (above). Collective.
  DistributedSimulation(const io::Config& config, Communicator comm);
  DistributedSimulation(const DistributedSimulation&) = delete;
  DistributedSimulation& operator=(const DistributedSimulation&) = delete;

  /// Advances one step. SimulationError on every process when the run becomes unstable (a node not finite or faster
  /// than time.max_speed, a membrane failing). Collective.
  void advance();
  bool finished() const;

  long step() const { return step_; }
  double time() const { return op_->fluid_state().time; }
  const Grid& grid() const { return grid_; }
  const DistributedOperator& op() const { return *op_; }
  std::size_t num_membranes() const { return membranes_.membranes.size(); }
  /// Membranes moved between processes so far.
  int migrations() const { return op_->migrations(); }

  /// The positions of all membranes in global order, on every process. Collective.
  std::vector<std::vector<Vec3>> gather_positions() const { return op_->ownership().gather_positions(); }
  /// The whole-grid fluid state, on every process. Collective.
  FluidState gather_fluid_state() const { return fluid_.gather(op_->fluid_state()); }

  /// What output and checkpoints read: the resolved configuration, the slab fluid solver (its decomposition), the
  /// membranes of the run (meshes, force objects, reference positions; all of them on every process) and the
  /// integrator (its history, of the owned nodes).
  const io::Config& config() const { return config_; }
  const SlabNavierStokesSolver& fluid() const { return fluid_; }
  const MembraneSet& membranes() const { return membranes_; }
  const MembraneIntegrator& integrator() const { return *integrator_; }

  /// Continues from a checkpoint of the same configuration written by any number of processes (or by Simulation):
  /// every process passes the whole checkpoint; the fluid is cut into this run's slabs and the membranes are owned
  /// by the processes holding their centroids. The integrator history (previous positions and guess errors, per node
  /// in global membrane order) is taken for the owned nodes. InputError as Simulation::restore. Collective.
  void restore(const io::Checkpoint& ck);

 private:
  void check_stability() const;

  io::Config config_;
  double dt_, end_time_, max_speed_;
  Grid grid_;
  SlabNavierStokesSolver fluid_;
  SlabIBCoupler coupler_;
  MembraneSet membranes_;
  std::unique_ptr<DistributedOperator> op_;
  std::unique_ptr<MembraneIntegrator> integrator_;
  long step_ = 0;
};

}  // namespace immerse
