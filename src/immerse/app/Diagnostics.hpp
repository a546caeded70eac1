#pragma once
// The per-step diagnostics of a run: the rows of diagnostics.csv (step, time, solver counts, then per membrane its
// volume, area, centroid, semi-axes, Taylor deformation D_xz and inclination, then the scenario's own columns).
// Shared by `immerse run` and the Python module.
#include <array>
#include <string>
#include <vector>

#include "immerse/app/Column.hpp"
#include "immerse/app/ScenarioRun.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

class Diagnostics {
 public:
  /// The columns for this configuration, number of membranes and scenario (which must outlive this object); a
  /// column kt, the nondimensional time, follows time where the configuration defines a shear rate.
  Diagnostics(const io::Config& config, std::size_t membranes, const ScenarioRun& scenario);

  const std::vector<Column>& columns() const { return columns_; }
  /// The row after the step r (the membranes' committed state).
  std::vector<double> row(const Simulation& sim, const StepRecord& r) const;

 private:
  const ScenarioRun& scenario_;
  double shear_rate_;
  std::vector<Column> columns_;
};

/// The principal semi-axes ordered by the coordinate axis their direction is closest to (a1 ~ x, a2 ~ y, a3 ~ z).
std::array<double, 3> semi_axes_along_xyz(const MembraneGeometry& g);
/// Inclination of the longest principal axis to the flow (x), in the x-z plane, in (-pi/2, pi/2].
double inclination(const MembraneGeometry& g);

}  // namespace immerse
