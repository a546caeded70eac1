#pragma once
// One run in one process: the grid, the fluid, the membranes, their coupling and the time integrator, built from a
// resolved configuration (Parameters), advanced step by step. run_command (cli/RunCommand.hpp) schedules callbacks
// (diagnostics, ParaView frames, checkpoints, progress) around advance() through SimulationInterface, which it
// implements with no MPI call.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "immerse/core/ThreadGovernor.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Mesh.hpp"
#include "immerse/simulation/EnergyBudget.hpp"
#include "immerse/simulation/ImmersedBoundaryOperator.hpp"
#include "immerse/simulation/SimulationInterface.hpp"
#include "immerse/simulation/StepRecord.hpp"
#include "immerse/timestep/AdaptiveStepper.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

class Simulation final : public SimulationInterface {
 public:
  /// Builds everything from `config` (already through apply_scenario). Throws InputError on inconsistent input
  /// (a membrane outside the box or too close to a wall, two membranes overlapping, bad meshes, ...).
  /// `stop_requested`, when given, is asked while [packing] places the cells: true throws StopRequested.
  explicit Simulation(const io::Config& config, const std::function<bool()>& stop_requested = {});

  /// Advances one accepted step (with step halving on failed solves, reported through `log`), then corrects the
  /// volume of the membranes with volume_correction = "normal_shift" (VolumeCorrection.hpp), and adds the step to
  /// the energy budget (EnergyBudget.hpp). Throws SimulationError naming step, time, membrane and quantity when the
  /// run becomes unstable.
  /// `stop_requested` is asked after each rejected attempt (StopRequested is thrown when it returns true).
  StepRecord advance(const Log& log, const StopQuery& stop_requested = {}) override;
  bool finished() const override;

  long step() const override { return step_; }
  double time() const override { return op_->fluid_state().time; }
  const io::Config& config() const override { return config_; }
  /// "packing: N copies of membrane[0], volume fraction ..., in T s" when [packing] placed the membranes, else empty.
  const std::string& packing_summary() const override { return packing_summary_; }
  const Grid& grid() const override { return grid_; }
  const Communicator& communicator() const override { return self_; }
  const ImmersedBoundaryOperator& op() const { return *op_; }
  std::size_t num_membranes() const override { return meshes_.size(); }
  const Mesh& mesh(std::size_t m) const override { return meshes_[m]; }
  const ElasticMembrane& membrane(std::size_t m) const override { return *membranes_[m]; }
  const std::vector<Vec3>& reference(std::size_t m) const { return references_[m]; }

  /// The energy budget: the fluid measures of the last state and the integrals since the start of the run (they
  /// continue across restarts), updated by advance().
  const EnergyBudget& energy_budget() const override { return budget_; }
  /// The fluid measures of the committed state, with the viscosity of the last step (FluidEnergy.hpp).
  FluidEnergy fluid_energy() const;
  /// The energies of membrane m at its committed positions.
  MembraneEnergy membrane_energy(std::size_t m) const;

  /// External nodal forces on membrane m (see ImmersedBoundaryOperator::set_applied_forces).
  void set_applied_forces(std::size_t m, const std::vector<Vec3>& F) override { op_->set_applied_forces(m, F); }

  std::vector<std::vector<Vec3>> positions() const override;
  std::vector<MembraneEnergy> membrane_energies() const override;
  double min_wall_distance() const override { return op_->min_wall_distance(); }
  double mean_velocity(int d) const override;
  const FluidParams& fluid_params() const override { return fluid_.params(); }
  const FluidState& committed_fluid() const override { return op_->fluid_state(); }
  double wall_shear_stress(bool upper, double mu, double wall_velocity_x) const override;
  StepTimings timings() const override { return op_->timings(); }
  std::string thread_policy() const override { return op_->thread_governor().policy(); }
  std::string thread_summary() const override { return op_->thread_governor().summary(); }
  void write_checkpoint(const std::filesystem::path& file, const Attributes& attributes,
                        const std::function<void(io::Checkpoint&)>& extra) const override;
  void write_frame(io::XdmfWriter* series, const std::filesystem::path& dir, int frame, const Attributes& attributes,
                   bool fluid_fields) const override;

  /// Everything needed to continue bitwise identically.
  io::Checkpoint checkpoint() const;
  /// Continues from a checkpoint of the same configuration (InputError naming the first differing key otherwise;
  /// time.end and output.* may differ). A checkpoint without an energy budget (EnergyBudget::saved_in) starts the
  /// budget's integrals at its state.
  void restore(const io::Checkpoint& ck) override;

 private:
  void check_stability(const StepRecord& r) const;
  /// Starts the energy budget at the committed state.
  void start_budget();

  io::Config config_;
  Communicator self_{MPI_COMM_SELF};
  double end_time_;   ///< time.end and time.max_speed, read once (the run's configuration does not change)
  double max_speed_;
  Grid grid_;
  ThreadGovernor threads_;  ///< first: sets OpenMP's thread count (cgroup quota) before the FFT plans are made
  NavierStokesSolver fluid_;
  IBCoupler coupler_;
  std::vector<Mesh> meshes_;
  std::vector<std::vector<Vec3>> references_, initial_;
  std::vector<std::unique_ptr<ElasticMembrane>> membranes_;
  /// The initial volume of each membrane whose volume is restored after every step (volume_correction).
  std::vector<std::optional<double>> corrected_volume_;
  std::vector<double> viscosity_ratio_;  ///< λ = μ_in/μ_out of each membrane
  std::unique_ptr<ImmersedBoundaryOperator> op_;
  std::unique_ptr<MembraneIntegrator> integrator_;
  AdaptiveStepper stepper_;
  EnergyBudget budget_;
  long step_ = 0;
  std::string packing_summary_;
};

}  // namespace immerse
