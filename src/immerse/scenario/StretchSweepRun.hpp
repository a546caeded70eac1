#pragma once
// rbc_stretch (§4.3): the force sweep of StretchSweep run step by step. Once the cell is steady under a force its
// diameters go into stretch.csv and the next force is applied; the run ends with the last force.
#include <optional>

#include "immerse/run/OutputTable.hpp"
#include "immerse/scenario/CellScenarioRun.hpp"
#include "immerse/scenario/StretchSweep.hpp"

namespace immerse {

class StretchSweepRun : public CellScenarioRun {
 public:
  StretchSweepRun();

  /// InputError unless `sim` runs in one process (the applied forces are not distributed).
  void attach(SimulationInterface& sim) override;
  void start(SimulationInterface&) override { sweep_->start(*sim_, 0); }
  void restore(const io::Checkpoint& ck, SimulationInterface&) override { sweep_->restore(ck, *sim_); }
  void save(io::Checkpoint& ck) const override { sweep_->save(ck); }

  std::vector<OutputTable*> tables() override { return {&table_}; }
  void after_step(SimulationInterface& sim, const std::function<void(const std::string&)>& log, std::ostream& out) override;
  bool done() const override { return sweep_->done(); }
  void announce(std::ostream& out) const override;
  void report_unfinished(std::ostream& out, const std::filesystem::path& checkpoint) const override;

 private:
  Simulation* sim_ = nullptr;          ///< from attach() on
  std::optional<StretchSweep> sweep_;  ///< from attach() on
  OutputTable table_;                  ///< stretch.csv: one row per force
};

}  // namespace immerse
