#pragma once
// The per-step diagnostics of a run: the rows of diagnostics.csv (step, time, solver counts, then per membrane its
// volume, area, centroid, semi-axes, Taylor deformation D_xz and inclination, then the scenario's own columns, then
// the energy budget: the fluid's kinetic energy, dissipation and powers, each membrane's energies, the total energy
// and the budget's residual, docs/energy-budget.md). Shared by `immerse run` (in one process or many) and the
// Python module.
#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "immerse/io/Config.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/run/Column.hpp"
#include "immerse/scenario/ScenarioRun.hpp"
#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

class Diagnostics {
 public:
  /// The columns for this configuration, number of membranes and scenario (which must outlive this object); a
  /// column kt, the nondimensional time, follows time where the configuration defines a shear rate.
  Diagnostics(const io::Config& config, std::size_t membranes, const ScenarioRun& scenario);

  const std::vector<Column>& columns() const { return columns_; }
  /// The row after the step r (the membranes' committed state), on every process. Collective.
  std::vector<double> row(const SimulationInterface& sim, const StepRecord& r) const;

 private:
  const ScenarioRun& scenario_;
  double shear_rate_;
  std::vector<Column> columns_;
};

/// Appends the values of the energy columns (the last ones) for the budget of a run whose membranes have the
/// energies `membranes`.
void add_energy_values(const EnergyBudget& budget, std::span<const MembraneEnergy> membranes,
                       std::vector<double>& row);

/// The log line of a restart from a checkpoint without an energy budget (written before the budget existed): the
/// integrals count from its step.
std::string energy_budget_note(const std::filesystem::path& checkpoint, long step, double time);

/// The principal semi-axes ordered by the coordinate axis their direction is closest to (a1 ~ x, a2 ~ y, a3 ~ z).
std::array<double, 3> semi_axes_along_xyz(const MembraneGeometry& g);
/// Taylor deformation (a - b)/(a + b) of the equivalent ellipsoid in the plane of shear: a >= b its two semi-axes
/// other than the one closest to y. Unlike D_xz, it averages over the whole surface, so node-scale roughness does not
/// bias it.
double ellipsoid_deformation(const MembraneGeometry& g);
/// Inclination of the longest principal axis to the flow (x), in the x-z plane, in (-pi/2, pi/2].
double inclination(const MembraneGeometry& g);

}  // namespace immerse
