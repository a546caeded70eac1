#pragma once
// Optical-tweezers stretching of a red blood cell (§4.3, Figs. 13-14): equal and opposite forces F along x,
// spread uniformly over the nodes inside two contact patches (discs of diameter scenario.patch_um, centred on the
// two ends of the cell's diameter along x; a node belongs to a patch when its reference position is within
// patch_um/2 of that end point). For each force of the sweep the run continues from the previous steady state
// until it is steady: both diameters change by less than scenario.steady_tol (relative) over one relaxation time
//   t_relax = mu R0 / mu0
// (fluid viscosity, cell radius, membrane shear modulus: the time in which viscous stress relaxes an elastic
// deformation of the cell). Diameters (CellDiameters): axial = the largest extent along x (the force axis);
// transverse = the largest extent along y (perpendicular to the force in the plane of the disc, which lies in x-y).
// The sweep's own state (which force, since when it waits, the last diameters) goes into the run's checkpoints, so
// that a sweep restarted from one continues bitwise identically.
// Verified by the tests RestartSweep.ForceSweepContinuesBitwiseFromAMidSweepCheckpoint and
// BadInputScenario.StretchPatchesAsWideAsTheCellAreRefused.
#include <vector>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/CellDiameters.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

class StretchSweep {
 public:
  explicit StretchSweep(const Simulation& sim);

  /// The forces (N) of the sweep, in order.
  const std::vector<double>& forces() const { return forces_; }
  /// Nodal forces for total stretching force F on each patch.
  std::vector<Vec3> nodal_loads(double F) const;
  double relaxation_time() const { return t_relax_; }
  int patch_nodes() const { return static_cast<int>(left_.size() + right_.size()); }

  /// Called after every accepted step: true once the cell is steady under the current force.
  bool steady(const Simulation& sim);
  /// True when the current force has waited max_relaxation_times without reaching a steady state.
  bool timed_out(const Simulation& sim) const;
  /// Starts force number `index` of the sweep at the current time (its loads are set on the simulation);
  /// index = forces().size() ends the sweep.
  void start(Simulation& sim, std::size_t index);
  /// Index of the force being applied (forces().size() once the sweep is done).
  std::size_t current() const { return current_; }
  bool done() const { return current_ >= forces_.size(); }

  void save(io::Checkpoint& ck) const;
  /// Continues a sweep from a checkpoint written by save() (and re-applies that force's loads).
  void restore(const io::Checkpoint& ck, Simulation& sim);

 private:
  std::vector<double> forces_;
  std::vector<std::size_t> left_, right_;
  std::size_t nodes_ = 0;
  double t_relax_ = 0, tol_ = 0, max_wait_ = 0;
  std::size_t current_ = 0;
  double t_start_ = 0, t_last_ = 0;
  CellDiameters last_;
};

}  // namespace immerse
