#pragma once
// The per-step diagnostics of a run: one row of diagnostics.csv (step, time, solver counts, then per membrane its
// volume, area, centroid, semi-axes, Taylor deformation D_xz and inclination; cell diameters for the red-cell
// scenarios; the mean flow velocity for the channel). Shared by the runner's CSV and the Python module.
#include <array>
#include <string>
#include <vector>

#include "immerse/io/Config.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

/// rbc_stretch: the force sweep of §4.3.
bool is_sweep(const io::Config& c);
/// rbc_channel: the duct of §4.4.
bool is_channel(const io::Config& c);
/// The red-cell scenarios, whose rows carry the cells' axial and transverse diameters.
bool is_cell_scenario(const io::Config& c);

/// A column of a CSV table: its name, its unit (UDUNITS form, "1" for a pure number) and what it holds.
struct Column {
  std::string name, unit, description;
};

/// The columns of diagnostics.csv for this configuration and number of membranes (a column kt, the
/// nondimensional time, follows time where the scenario defines a shear rate).
std::vector<Column> diagnostics_column_info(const io::Config& config, std::size_t membranes);
/// The table of columns that is written beside a CSV file (NAME.columns.csv): column,unit,description.
std::string column_table(const std::vector<Column>& columns);
/// The column names of diagnostics.csv for this configuration and number of membranes.
std::vector<std::string> diagnostics_columns(const io::Config& config, std::size_t membranes);
/// The row of diagnostics.csv after the step r (the membranes' committed state).
std::vector<double> diagnostics_row(const Simulation& sim, const StepRecord& r);

/// The principal semi-axes ordered by the coordinate axis their direction is closest to (a1 ~ x, a2 ~ y, a3 ~ z).
std::array<double, 3> semi_axes_along_xyz(const MembraneGeometry& g);
/// Inclination of the longest principal axis to the flow (x), in the x-z plane, in (-pi/2, pi/2].
double inclination(const MembraneGeometry& g);

}  // namespace immerse
