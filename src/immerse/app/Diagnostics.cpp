#include "immerse/app/Diagnostics.hpp"

#include <cmath>
#include <stdexcept>

#include "immerse/app/Scenario.hpp"
#include "immerse/app/ShearPlaneProfile.hpp"
#include "immerse/membrane/CellDiameters.hpp"

namespace immerse {

namespace {

// Units as UDUNITS writes them ("1": a number without unit).
const std::vector<Column> kStepColumns{
    {"step", "1", "time step number"},
    {"time", "s", "simulated time t"},
    {"dt", "s", "step size that reached this step (0 on the first row of a series: the initial state or the restart)"},
    {"newton_its", "1", "nonlinear iterations of the step"},
    {"gmres_its", "1", "GMRES iterations of the step (jfnk)"},
    {"fluid_solves", "1", "fluid solves (residual evaluations) of the step"},
    {"residual", "1", "final relative Newton residual ||g|| / ||X|| (0 for explicit schemes)"},
    {"wall_s", "s", "wall-clock time of the step"}};
const Column kShearTime{"kt", "1", "nondimensional time: shear rate k times t"};
const std::vector<Column> kMembraneColumns{
    {"volume", "m^3", "enclosed volume"},
    {"area", "m^2", "surface area"},
    {"cx", "m", "centroid x"},
    {"cy", "m", "centroid y"},
    {"cz", "m", "centroid z"},
    {"a1", "m", "semi-axis of the equivalent ellipsoid (same volume inertia) closest to x"},
    {"a2", "m", "semi-axis of the equivalent ellipsoid closest to y"},
    {"a3", "m", "semi-axis of the equivalent ellipsoid closest to z"},
    {"D_xz", "1", "Taylor deformation (L - B) / (L + B) of the section by the x-z plane through the centroid"},
    {"theta", "rad", "inclination of the longest principal axis to x in the x-z plane"}};
const std::vector<Column> kCellColumns{{"axial_um", "um", "largest extent of the cell along the force (x) or the flow (y)"},
                                       {"transverse_um", "um", "largest extent along either other coordinate axis"}};
const Column kMeanVelocity{"mean_velocity", "m/s", "mean fluid velocity along the flow (y) over the box"};

// The axis along which a cell's axial diameter is measured: the force (x) or the flow (y).
int cell_axis(const io::Config& c) { return is_channel(c) ? 1 : 0; }

// Mean fluid velocity along the flow (y) over the box: the flow rate through a cross-section over its area
// (on the periodic y axis every y-face is distinct, and they tile the box).
double mean_flow_velocity(const Simulation& sim) {
  const auto& v = sim.op().fluid_state().u[1].values();
  double sum = 0;
  for (double x : v) sum += x;
  return sum / double(v.size());
}

}  // namespace

bool is_sweep(const io::Config& c) { return c.get<std::string>("scenario.kind") == "rbc_stretch"; }
bool is_channel(const io::Config& c) { return c.get<std::string>("scenario.kind") == "rbc_channel"; }
bool is_cell_scenario(const io::Config& c) { return is_sweep(c) || is_channel(c); }

std::vector<Column> diagnostics_column_info(const io::Config& config, std::size_t membranes) {
  auto cols = kStepColumns;
  if (shear_rate(config) > 0) cols.insert(cols.begin() + 2, kShearTime);
  for (std::size_t m = 0; m < membranes; ++m) {
    std::string prefix, whose;
    if (membranes > 1) {
      prefix.append("m").append(std::to_string(m)).append("_");
      whose = " of membrane[" + std::to_string(m) + "]";
    }
    for (const auto& c : kMembraneColumns) cols.push_back({prefix + c.name, c.unit, c.description + whose});
    if (is_cell_scenario(config))
      for (const auto& c : kCellColumns) cols.push_back({prefix + c.name, c.unit, c.description + whose});
  }
  if (is_channel(config)) cols.push_back(kMeanVelocity);
  return cols;
}

std::vector<std::string> diagnostics_columns(const io::Config& config, std::size_t membranes) {
  std::vector<std::string> names;
  for (const auto& c : diagnostics_column_info(config, membranes)) names.push_back(c.name);
  return names;
}

std::string column_table(const std::vector<Column>& columns) {
  std::string out = "column,unit,description\n";
  for (const auto& c : columns) {
    if ((c.name + c.unit + c.description).find_first_of(",\"\n") != std::string::npos)
      throw std::logic_error("column_table: column " + c.name + " has a comma, quote or line break in its text");
    out += c.name + "," + c.unit + "," + c.description + "\n";
  }
  return out;
}

// The principal semi-axes ordered by the coordinate axis their direction is closest to (a1 ~ x, a2 ~ y, a3 ~ z),
// so that each column follows one axis of the shape in time (Figs. 4-5) instead of swapping when lengths cross.
std::array<double, 3> semi_axes_along_xyz(const MembraneGeometry& g) {
  std::array<double, 3> a{};
  std::array<bool, 3> used{};
  for (int c = 0; c < 3; ++c) {
    int best = -1;
    for (int k = 0; k < 3; ++k)
      if (!used[k] && (best < 0 || std::abs(g.axes[k][c]) > std::abs(g.axes[best][c]))) best = k;
    used[best] = true;
    a[c] = g.semi_axes[best];
  }
  return a;
}

// Inclination of the long axis to the flow: angle in (-pi/2, pi/2] of the longest principal axis in the x-z plane.
double inclination(const MembraneGeometry& g) {
  double t = std::atan2(g.axes[0].z, g.axes[0].x);
  if (t > M_PI / 2) t -= M_PI;
  if (t <= -M_PI / 2) t += M_PI;
  return t;
}

std::vector<double> diagnostics_row(const Simulation& sim, const StepRecord& r) {
  std::vector<double> row{double(r.step), r.time};
  if (const double k = shear_rate(sim.config()); k > 0) row.push_back(k * r.time);
  row.insert(row.end(), {r.dt,
                          double(r.stats.newton_its),
                          double(r.stats.gmres_its),
                          double(r.stats.fluid_solves),
                          r.stats.residual,
                          r.wall_seconds});
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const auto X = sim.op().membrane_positions(m);
    const MembraneGeometry g = measure(sim.mesh(m), X);
    const ShearPlaneProfile p = shear_plane_profile(sim.mesh(m), X, g.centroid);
    const auto a = semi_axes_along_xyz(g);
    row.insert(row.end(), {g.volume, g.area, g.centroid.x, g.centroid.y, g.centroid.z, a[0], a[1], a[2], p.D_xz,
                           inclination(g)});
    if (is_cell_scenario(sim.config())) {
      const CellDiameters d = cell_diameters(X, cell_axis(sim.config()));
      row.insert(row.end(), {d.axial * 1e6, d.transverse * 1e6});
    }
  }
  if (is_channel(sim.config())) row.push_back(mean_flow_velocity(sim));
  return row;
}

}  // namespace immerse
