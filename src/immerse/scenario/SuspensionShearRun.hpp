#pragma once
// suspension_shear: cells between two walls z = const sliding along x (plane Couette flow at shear rate
// k = (U_upper − U_lower) / L_z). Each row of diagnostics.csv carries the volume fraction of the membranes, the shear
// stress on each wall and the relative viscosity
//
//   η_rel = (τ_lower + τ_upper) / (2 μ k),
//
// the suspension's effective viscosity over the suspending fluid's (1 without cells). τ is the stress the viscous
// term applies at the wall (wall_shear_stress, src/immerse/fluid/FluidDiagnostics.hpp); averaged in time over the
// sheared steady state it is the effective viscosity a rheometer with this gap measures
// (docs/scenarios/suspension-shear.md).
// Verified by: the tests SuspensionShear.* (tests/test_run_suspension.cpp) and FluidDiagnostics.WallShearStress*.
#include "immerse/scenario/ScenarioRun.hpp"

namespace immerse {

class SuspensionShearRun : public ScenarioRun {
 public:
  explicit SuspensionShearRun(const io::Config& config);

  std::vector<Column> run_columns() const override;
  void add_run_values(const SimulationInterface& sim, std::vector<double>& row) const override;

 private:
  double mu_, shear_rate_, box_volume_;
  double lower_x_, upper_x_;  // wall velocities along x
};

}  // namespace immerse
