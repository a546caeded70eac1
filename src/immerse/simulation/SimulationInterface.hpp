#pragma once
// What a run asks of a simulation, in one process or over many: the time loop of `immerse run`, its output, its
// diagnostics and the scenarios' work go through this interface, so each is written once. Simulation (one process)
// and DistributedSimulation (the grid in slabs over MPI processes) implement it.
//
// Methods marked collective are called by every process of communicator() in the same order and give every process
// the same result; on one process they make no MPI call. The others are local. Files are written by write_checkpoint
// and write_frame together; everything else a run writes is written by rank 0.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/io/XdmfWriter.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Mesh.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/simulation/EnergyBudget.hpp"
#include "immerse/simulation/StepRecord.hpp"
#include "immerse/simulation/StepTimings.hpp"

namespace immerse {

class SimulationInterface {
 public:
  using Log = std::function<void(const std::string&)>;
  using StopQuery = std::function<bool()>;
  using Attributes = std::vector<std::pair<std::string, std::string>>;

  SimulationInterface() = default;
  SimulationInterface(const SimulationInterface&) = delete;
  SimulationInterface& operator=(const SimulationInterface&) = delete;
  virtual ~SimulationInterface() = default;

  virtual const io::Config& config() const = 0;
  virtual const Grid& grid() const = 0;
  /// The processes of the run (MPI_COMM_SELF in one process).
  virtual const Communicator& communicator() const = 0;
  virtual long step() const = 0;
  virtual double time() const = 0;
  virtual bool finished() const = 0;
  virtual std::size_t num_membranes() const = 0;
  virtual const Mesh& mesh(std::size_t m) const = 0;
  /// The force object of membrane m (every process holds all of them).
  virtual const ElasticMembrane& membrane(std::size_t m) const = 0;
  /// "packing: ..." when [packing] placed the membranes, else empty.
  virtual const std::string& packing_summary() const = 0;
  /// The energy budget (the same on every process).
  virtual const EnergyBudget& energy_budget() const = 0;
  /// One header line on how the run is spread over processes ("" in one process).
  virtual std::string decomposition_summary() const { return ""; }
  /// Membranes moved from one process to another so far (0 in one process).
  virtual int migrations() const { return 0; }

  /// Advances one accepted step: the step is halved and retried on a failed solve (each rejection reported through
  /// `log`), `stop_requested` is asked after each rejected attempt (StopRequested thrown, on every process, when
  /// it returns true on any). SimulationError naming step, time and what diverged when the run becomes unstable.
  /// Collective.
  virtual StepRecord advance(const Log& log, const StopQuery& stop_requested = {}) = 0;
  /// Continues from a checkpoint of the same configuration (InputError otherwise). Collective.
  virtual void restore(const io::Checkpoint& ck) = 0;
  /// External nodal forces on membrane m (InputError where the run cannot apply them). Collective.
  virtual void set_applied_forces(std::size_t m, const std::vector<Vec3>& F) = 0;

  /// The committed positions of every membrane. Collective.
  virtual std::vector<std::vector<Vec3>> positions() const = 0;
  /// The energies of every membrane at its committed positions (SimulationError if one cannot be evaluated).
  /// Collective.
  virtual std::vector<MembraneEnergy> membrane_energies() const = 0;
  /// The closest approach of a node to a wall (not finite: no walls, or a node outside the box). Collective.
  virtual double min_wall_distance() const = 0;
  /// The mean over the box of the fluid velocity component d (on a periodic axis d: the flow rate through a
  /// cross-section over its area). Collective.
  virtual double mean_velocity(int d) const = 0;
  /// The body force of the step that reached the committed state (N/m^3): fluid.body_force, plus with fluid.flow_rate
  /// the force that step added along the flow axis.
  Vec3 step_body_force() const { return step_params(fluid_params(), committed_fluid()).body_force; }
  /// The fluid's parameters and committed state (this process's slab of it when distributed).
  virtual const FluidParams& fluid_params() const = 0;
  virtual const FluidState& committed_fluid() const = 0;
  /// The mean shear stress μ (1 + χ) ∂u_x/∂z on the lower or upper z wall moving at wall_velocity_x along x
  /// (wall_shear_stress of FluidDiagnostics.hpp). Collective.
  virtual double wall_shear_stress(bool upper, double mu, double wall_velocity_x) const = 0;

  /// Wall time of this process in each part of the coupled step since the start of the run.
  virtual StepTimings timings() const = 0;
  /// How the OpenMP threads are chosen, and a summary line of how they were used (ThreadGovernor).
  virtual std::string thread_policy() const = 0;
  virtual std::string thread_summary() const = 0;

  /// Writes the checkpoint of the committed state to `file` atomically, with `attributes` (the provenance) and the
  /// entries `extra` adds (a scenario's state). WriteError on failure. Collective.
  virtual void write_checkpoint(const std::filesystem::path& file, const Attributes& attributes,
                                const std::function<void(io::Checkpoint&)>& extra) const = 0;
  /// Writes ParaView frame `frame` into `dir` (the fluid too when `fluid_fields`) and appends it to `series`, which
  /// rank 0 passes (null elsewhere). SimulationError if a membrane's forces cannot be evaluated, WriteError on a
  /// failed write. Collective.
  virtual void write_frame(io::XdmfWriter* series, const std::filesystem::path& dir, int frame,
                           const Attributes& attributes, bool fluid_fields) const = 0;
};

}  // namespace immerse
