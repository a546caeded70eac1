#pragma once
// capsule_constriction: capsules carried through the constriction of wall[0] (WallGeometry, shape = "constriction";
// the square channel with a throat of Park & Dimitrakopoulos 2013, Soft Matter 9:8844) at the flow rate
// fluid.flow_rate along its axis t. In diagnostics.csv, per membrane, its extents along x, y and z (the largest
// minus the least node coordinate: Park & Dimitrakopoulos' lengths l_x, l_y, l_z), the centroid's position along t
// relative to the throat's centre (nearest periodic image), and whether the centroid is in the throat (1) or not (0);
// for the run, the flow rate through the channel (the mean of u·t over the box times its cross-section) and the mean
// pressure gradient holding it (the body force along t, controller included).
// Verified by the tests CapsuleConstriction.* (tests/test_run_constriction.cpp: the quick scenario's passage, bad
// input) and DuctFlow.FlowRateIsHeldThroughAConstriction (tests/test_walls.cpp).
#include <vector>

#include "immerse/scenario/ScenarioRun.hpp"

namespace immerse {

class CapsuleConstrictionRun : public ScenarioRun {
 public:
  std::vector<Column> membrane_columns() const override;
  std::vector<Column> run_columns() const override;
  void add_membrane_values(const std::vector<Vec3>& X, std::vector<double>& row) const override;
  void add_run_values(const SimulationInterface& sim, std::vector<double>& row) const override;
  void attach(SimulationInterface& sim) override;

 private:
  int axis_ = 0;                      // t, a coordinate axis
  double centre_ = 0;                 // the throat's centre along t (m)
  double half_length_ = 0;            // half the throat's length (m)
  double period_ = 0;                 // the box's length along t (m)
  double section_ = 0;                // the box's cross-section normal to t (m^2)
  std::vector<unsigned char> fluid_;  // φ > 0 at each point of component t
};

}  // namespace immerse
