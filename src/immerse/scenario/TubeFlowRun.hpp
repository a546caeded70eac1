#pragma once
// tube_flow: flow through the tube of wall[0] (WallGeometry), driven by fluid.body_force. In diagnostics.csv the flow
// rate through the tube's cross-section,
//   Q = (1/|P|) ∫_fluid u·t dV     (t the tube's axis, |P| the axis's length in one period of the box),
// Poiseuille's π G R⁴ / 8μ for the body force's component G along t, and their ratio, the apparent viscosity of the
// tube's content over the fluid's (1 for the fluid alone; above 1 with cells: the Fåhræus–Lindqvist measure of Pries,
// Neuhaus & Gaehtgens 1992, Am. J. Physiol. 263:H1770). With cells (rbc_tube): the tube hematocrit, their volume
// over the tube's, and the cell-free layer, R minus the mean over slices along the axis (one grid spacing long) of the
// outermost node's distance from the axis.
// Verified by the test TubeFlow.ScenarioReachesPoiseuilleFlowRate (the scenario file's run: flow rate within 1 % of
// π G R⁴ / 8μ) and TubeFlow.* in tests/test_walls.cpp (the same against refinement and a tube at 30°).
#include <optional>
#include <vector>

#include "immerse/scenario/ScenarioRun.hpp"

namespace immerse {

class TubeFlowRun : public ScenarioRun {
 public:
  std::vector<Column> run_columns() const override;
  void add_run_values(const SimulationInterface& sim, std::vector<double>& row) const override;
  void attach(SimulationInterface& sim) override;

 private:
  struct Tube {
    std::array<std::vector<unsigned char>, 3> fluid;  ///< φ > 0 at each velocity point
    Vec3 axis, centre;
    double period = 0, poiseuille = 0;  ///< |P| (m); π R⁴ / 8μ (m^3/s per N/m^3 of body force)
    double radius = 0, fluid_volume = 0;  ///< R (m); the fluid's volume in the box (m^3)
  };
  std::optional<Tube> tube_;
};

}  // namespace immerse
