#pragma once
// rbc_channel (§4.4): the cells' diameters along the flow (y), and in diagnostics.csv the mean flow velocity, the flow
// rate, the pressure drop that the body force of the last step stands for (fluid.body_force, plus what
// fluid.flow_rate added) and the relative apparent viscosity
//   μ_app / μ = U_0 / U,
// U the mean velocity along y and U_0 that of the cell-free fluid (the discrete Poiseuille flow of PoiseuilleFlow.hpp)
// under that body force: the duct's resistance with the cells over that of the plasma alone, the measure of the
// Fåhræus–Lindqvist effect (Pries, Neuhaus & Gaehtgens 1992, Am. J. Physiol. 263:H1770).
// Verified by the tests RbcChannel.ThirtyTwoCellsInAPoiseuilleDuctWithTheirDiagnostics (1 at the start, then above 1;
// the flow rate and the pressure drop from the mean velocity and the body force) and
// RbcChannel.FlowRateIsHeldWhileThePressureDropRises (the pressure drop of the force fluid.flow_rate adds).
#include <optional>

#include "immerse/scenario/CellScenarioRun.hpp"

namespace immerse {

class ChannelRun : public CellScenarioRun {
 public:
  ChannelRun() : CellScenarioRun(1) {}

  std::vector<Column> run_columns() const override;
  void add_run_values(const SimulationInterface& sim, std::vector<double>& row) const override;

 private:
  struct Duct {
    double section = 0;    ///< Lx Lz (m^2)
    double period = 0;     ///< Ly (m)
    double cell_free = 0;  ///< U_0 per unit body force along y (m^4/(N s)); NaN when a wall moves
  };
  /// The duct of `sim`'s configuration, computed at the first row.
  const Duct& duct(const SimulationInterface& sim) const;
  mutable std::optional<Duct> duct_;
};

}  // namespace immerse
