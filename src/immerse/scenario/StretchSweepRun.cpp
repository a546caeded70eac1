#include "immerse/scenario/StretchSweepRun.hpp"

#include <ostream>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/CellDiameters.hpp"
#include "immerse/simulation/Simulation.hpp"

namespace immerse {

// A run continued in its folder keeps the rows of the forces done before its checkpoint.
StretchSweepRun::StretchSweepRun()
    : CellScenarioRun(0),
      table_("stretch",
             {{"force_pN", "pN", "stretching force on each contact patch"},
              {"axial_um", "um", "steady diameter along the force (x)"},
              {"transverse_um", "um", "steady largest diameter across the force"}},
             [this](long row, double) { return row < long(sweep_->current()); }) {}

// A force that has waited scenario.max_relaxation_times without a steady state is recorded anyway.
void StretchSweepRun::attach(SimulationInterface& sim) {
  sim_ = dynamic_cast<Simulation*>(&sim);
  if (!sim_)
    throw InputError("scenario.kind = \"rbc_stretch\": its forces on the contact patches are not distributed over " +
                     std::to_string(sim.communicator().size()) + " MPI processes (run it in one process)");
  sweep_.emplace(*sim_);
}

void StretchSweepRun::after_step(SimulationInterface&, const std::function<void(const std::string&)>& log,
                                 std::ostream& out) {
  Simulation& sim = *sim_;
  const bool steady = sweep_->steady(sim);
  if (!steady && !sweep_->timed_out(sim)) return;
  const double F = sweep_->forces()[sweep_->current()];
  if (!steady)
    log("force " + std::to_string(F * 1e12) + " pN: not steady after scenario.max_relaxation_times; recorded anyway");
  const CellDiameters d = cell_diameters(sim.op().membrane_positions(0), 0);
  table_.row({F * 1e12, d.axial * 1e6, d.transverse * 1e6});
  out << "\nforce " << F * 1e12 << " pN: axial " << d.axial * 1e6 << " um, transverse " << d.transverse * 1e6
      << " um (t = " << sim.time() << " s)\n";
  sweep_->start(sim, sweep_->current() + 1);
}

void StretchSweepRun::announce(std::ostream& out) const {
  out << "rbc_stretch: " << sweep_->patch_nodes() << " nodes in the two contact patches, relaxation time "
      << sweep_->relaxation_time() << " s\n";
}

void StretchSweepRun::report_unfinished(std::ostream& out, const std::filesystem::path& checkpoint) const {
  if (sweep_->done()) return;
  out << "\nrbc_stretch: time.end reached during force " << sweep_->current() + 1 << " of " << sweep_->forces().size()
      << " (" << sweep_->forces()[sweep_->current()] * 1e12 << " pN); continue the sweep with --restart "
      << checkpoint.string() << " and a later time.end\n";
}

}  // namespace immerse
