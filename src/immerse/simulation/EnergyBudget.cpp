#include "immerse/simulation/EnergyBudget.hpp"

#include <cmath>

#include "immerse/simulation/CheckpointEntries.hpp"

namespace immerse {

// The one place that knows how ElasticMembrane splits its energy.
MembraneEnergy membrane_energy(const ElasticMembrane& m, std::span<const Vec3> X) { return m.energy_parts(X); }

double total_energy(double kinetic, std::span<const MembraneEnergy> membranes) {
  double total = kinetic;
  for (const auto& m : membranes) total += m.total();
  return total;
}

void EnergyBudget::start(double total, const FluidEnergy& fluid) {
  fluid_ = fluid;
  initial_ = total;
  dissipated_ = walls_work_ = body_work_ = 0;
}

void EnergyBudget::advance(double dt, const FluidEnergy& fluid) {
  dissipated_ += 0.5 * dt * (fluid_.dissipation + fluid.dissipation);
  walls_work_ += 0.5 * dt * (fluid_.walls + fluid.walls);
  body_work_ += 0.5 * dt * (fluid_.body + fluid.body);
  fluid_ = fluid;
}

std::vector<std::pair<std::string, double>> EnergyBudget::entries() const {
  return {{"energy.initial_total", initial_},   {"energy.dissipated", dissipated_},
          {"energy.walls_work", walls_work_},   {"energy.body_work", body_work_},
          {"energy.kinetic", fluid_.kinetic},   {"energy.dissipation", fluid_.dissipation},
          {"energy.walls_power", fluid_.walls}, {"energy.body_power", fluid_.body}};
}

bool EnergyBudget::saved_in(const io::Checkpoint& ck) { return ck.has("energy.initial_total"); }

bool EnergyBudget::restore(const io::Checkpoint& ck) {
  if (!saved_in(ck)) return false;
  const CheckpointEntries entries(ck);
  const auto value = [&](const std::string& name) {
    const double v = ck.get_double(name);
    return entries.number(name, v, std::isfinite(v), "finite");
  };
  EnergyBudget b;
  b.initial_ = value("energy.initial_total");
  b.dissipated_ = value("energy.dissipated");
  b.walls_work_ = value("energy.walls_work");
  b.body_work_ = value("energy.body_work");
  b.fluid_ = {value("energy.kinetic"), value("energy.dissipation"), value("energy.walls_power"),
              value("energy.body_power")};
  *this = b;
  return true;
}

}  // namespace immerse
