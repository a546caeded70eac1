#include "immerse/scenario/SuspensionShearRun.hpp"

#include "immerse/scenario/Scenario.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

SuspensionShearRun::SuspensionShearRun(const io::Config& config)
    : mu_(config.get<double>("fluid.mu")),
      shear_rate_(shear_rate(config)),
      box_volume_(config.get<double>("domain.Lx") * config.get<double>("domain.Ly") * config.get<double>("domain.Lz")),
      lower_x_(config.get<Vec3>("boundary.z_lower_velocity").x),
      upper_x_(config.get<Vec3>("boundary.z_upper_velocity").x) {}

std::vector<Column> SuspensionShearRun::run_columns() const {
  return {{"volume_fraction", "1", "volume enclosed by the membranes over the box volume (hematocrit for red cells)"},
          {"wall_stress_lower", "Pa", "mean shear stress mu (1 + chi) du_x/dz on the wall z = z_lower"},
          {"wall_stress_upper", "Pa", "mean shear stress mu (1 + chi) du_x/dz on the wall z = z_upper"},
          {"relative_viscosity", "1", "mean of the two wall stresses over mu k: the suspension's viscosity over the "
                                      "suspending fluid's"}};
}

void SuspensionShearRun::add_run_values(const SimulationInterface& sim, std::vector<double>& row) const {
  double volume = 0;
  const auto X = sim.positions();
  for (std::size_t m = 0; m < X.size(); ++m) volume += measure(sim.mesh(m), X[m]).volume;
  const double lower = sim.wall_shear_stress(false, mu_, lower_x_);
  const double upper = sim.wall_shear_stress(true, mu_, upper_x_);
  row.insert(row.end(), {volume / box_volume_, lower, upper, 0.5 * (lower + upper) / (mu_ * shear_rate_)});
}

}  // namespace immerse
