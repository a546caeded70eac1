#include "immerse/simulation/Diagnostics.hpp"

#include <cmath>

#include "immerse/membrane/CellDiameters.hpp"
#include "immerse/simulation/ShearPlaneProfile.hpp"

namespace immerse {

namespace {

const std::vector<std::string> kStepColumns{"step",         "time",     "dt",       "newton_its",
                                            "gmres_its",    "fluid_solves", "residual", "wall_s"};
const std::vector<std::string> kMembraneColumns{"volume", "area", "cx", "cy", "cz", "a1", "a2", "a3", "D_xz", "theta"};

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

std::vector<std::string> diagnostics_columns(const io::Config& config, std::size_t membranes) {
  auto cols = kStepColumns;
  for (std::size_t m = 0; m < membranes; ++m) {
    std::string prefix;
    if (membranes > 1) prefix.append("m").append(std::to_string(m)).append("_");
    for (const auto& c : kMembraneColumns) cols.push_back(prefix + c);
    if (is_cell_scenario(config))
      for (const char* c : {"axial_um", "transverse_um"}) cols.push_back(prefix + c);
  }
  if (is_channel(config)) cols.push_back("mean_velocity");
  return cols;
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
  std::vector<double> row{double(r.step),
                          r.time,
                          r.dt,
                          double(r.stats.newton_its),
                          double(r.stats.gmres_its),
                          double(r.stats.fluid_solves),
                          r.stats.residual,
                          r.wall_seconds};
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
