#include "immerse/run/Diagnostics.hpp"

#include <cmath>

#include "immerse/io/TomlFormat.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/scenario/ShearPlaneProfile.hpp"

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
    {"D_ellipsoid", "1", "Taylor deformation (a - b) / (a + b) of the equivalent ellipsoid in the x-z plane"},
    {"theta", "rad", "inclination of the longest principal axis to x in the x-z plane"},
    {"min_area_ratio", "1",
     "least ratio of an element's area to its area in the stress-free reference (the local area dilation J)"}};
// The energy budget (docs/energy-budget.md): the fluid's measures, each membrane's energies, then the run's totals.
const std::vector<Column> kFluidEnergyColumns{
    {"E_kinetic", "J", "kinetic energy of the fluid: rho/2 sum of u^2 h^3 over the velocity unknowns"},
    {"dissipation", "W",
     "viscous dissipation rate: mu sum of |G u|^2 h^3 (plus mu chi |S|^2/2 h^3 with a viscosity contrast)"},
    {"P_walls", "W", "power the moving walls put into the fluid"},
    {"P_body", "W", "power of the body force: f_body . sum of u h^3"}};
const std::vector<Column> kMembraneEnergyColumns{{"E_elastic", "J", "in-plane elastic energy"},
                                                 {"E_bending", "J", "bending energy (0 without one)"},
                                                 {"E_constraint", "J", "energy of the volume and area constraints"}};
const std::vector<Column> kBudgetColumns{
    {"E_total", "J", "E_kinetic plus the energies of every membrane"},
    {"budget_residual", "J",
     "E_total - E_total(t0) + integral of dissipation - integral of (P_walls + P_body) (trapezoidal rule over every "
     "step)"}};

}  // namespace

Diagnostics::Diagnostics(const io::Config& config, std::size_t membranes, const ScenarioRun& scenario)
    : scenario_(scenario), shear_rate_(shear_rate(config)), columns_(kStepColumns) {
  if (shear_rate_ > 0) columns_.insert(columns_.begin() + 2, kShearTime);
  auto per_membrane = kMembraneColumns;
  for (const auto& c : scenario.membrane_columns()) per_membrane.push_back(c);
  const auto add_membranes = [&](const std::vector<Column>& columns) {
    for (std::size_t m = 0; m < membranes; ++m) {
      std::string prefix, whose;
      if (membranes > 1) {
        prefix.append("m").append(std::to_string(m)).append("_");
        whose = " of membrane[" + std::to_string(m) + "]";
      }
      for (const auto& c : columns) columns_.push_back({prefix + c.name, c.unit, c.description + whose});
    }
  };
  add_membranes(per_membrane);
  for (const auto& c : scenario.run_columns()) columns_.push_back(c);
  columns_.insert(columns_.end(), kFluidEnergyColumns.begin(), kFluidEnergyColumns.end());
  add_membranes(kMembraneEnergyColumns);
  columns_.insert(columns_.end(), kBudgetColumns.begin(), kBudgetColumns.end());
}

void add_energy_values(const EnergyBudget& budget, std::span<const MembraneEnergy> membranes,
                       std::vector<double>& row) {
  const FluidEnergy& f = budget.fluid();
  row.insert(row.end(), {f.kinetic, f.dissipation, f.walls, f.body});
  for (const auto& m : membranes) row.insert(row.end(), {m.elastic, m.bending, m.constraint});
  const double total = total_energy(f.kinetic, membranes);
  row.insert(row.end(), {total, budget.residual(total)});
}

std::string energy_budget_note(const std::filesystem::path& checkpoint, long step, double time) {
  return "# energy budget: " + checkpoint.string() +
         " holds none (written before the budget was saved): the integrals of budget_residual start again at its "
         "step " +
         std::to_string(step) + ", t = " + io::format_number(time) + "\n";
}

// The semi-axes follow the coordinate axes, so that each column follows one axis of the shape in time (Figs. 4-5)
// instead of swapping when lengths cross.
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

double ellipsoid_deformation(const MembraneGeometry& g) {
  int normal = 0;  // the principal axis closest to y, normal to the plane of shear
  for (int k = 1; k < 3; ++k)
    if (std::abs(g.axes[k].y) > std::abs(g.axes[normal].y)) normal = k;
  const double a = g.semi_axes[normal == 0 ? 1 : 0], b = g.semi_axes[normal == 2 ? 1 : 2];
  return a + b > 0 ? (a - b) / (a + b) : 0;
}

double inclination(const MembraneGeometry& g) {
  double t = std::atan2(g.axes[0].z, g.axes[0].x);
  if (t > M_PI / 2) t -= M_PI;
  if (t <= -M_PI / 2) t += M_PI;
  return t;
}

std::vector<double> Diagnostics::row(const SimulationInterface& sim, const StepRecord& r) const {
  std::vector<double> row{double(r.step), r.time};
  if (shear_rate_ > 0) row.push_back(shear_rate_ * r.time);
  row.insert(row.end(), {r.dt,
                          double(r.stats.newton_its),
                          double(r.stats.gmres_its),
                          double(r.stats.fluid_solves),
                          r.stats.residual,
                          r.wall_seconds});
  const std::vector<std::vector<Vec3>> positions = sim.positions();
  for (std::size_t m = 0; m < sim.num_membranes(); ++m) {
    const std::vector<Vec3>& X = positions[m];
    const MembraneGeometry g = measure(sim.mesh(m), X);
    const ShearPlaneProfile p = shear_plane_profile(sim.mesh(m), X, g.centroid);
    const auto a = semi_axes_along_xyz(g);
    row.insert(row.end(), {g.volume, g.area, g.centroid.x, g.centroid.y, g.centroid.z, a[0], a[1], a[2], p.D_xz,
                           ellipsoid_deformation(g), inclination(g),
                           least_area_ratio(sim.mesh(m), X, sim.membrane(m).reference_element_areas()).ratio});
    scenario_.add_membrane_values(X, row);
  }
  scenario_.add_run_values(sim, row);
  add_energy_values(sim.energy_budget(), sim.membrane_energies(), row);
  return row;
}

}  // namespace immerse
