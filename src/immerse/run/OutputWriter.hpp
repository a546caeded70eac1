#pragma once
// The output of `immerse run`: its folder (locked; another run's is refused unless continued or replaced), the first
// files, and the callbacks that write diagnostics rows, ParaView frames and checkpoints on their schedules. A restart
// into another folder branches the run: a new series that begins at the checkpoint's step.
//
// In a run over several MPI processes rank 0 alone takes the folder and writes the tables, the resolved configuration,
// the copies of mesh files and the XDMF series; frames and checkpoints are written by all processes together
// (SimulationInterface). A write that fails on rank 0 fails on every process (WriteError). Construction is local;
// create() and the callbacks are collective.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "immerse/io/OutputFolder.hpp"
#include "immerse/io/Provenance.hpp"
#include "immerse/io/XdmfWriter.hpp"
#include "immerse/run/Callback.hpp"
#include "immerse/run/CommandLine.hpp"
#include "immerse/run/Diagnostics.hpp"
#include "immerse/run/MeshCopies.hpp"
#include "immerse/run/OutputSchedule.hpp"
#include "immerse/run/OutputTable.hpp"
#include "immerse/scenario/ScenarioRun.hpp"
#include "immerse/simulation/SimulationInterface.hpp"

namespace immerse {

class OutputWriter {
 public:
  /// Checks the folder and, when the run continues in it, reads the rows of its tables to keep (InputError on a
  /// folder the run may not take or a damaged table; on rank 0 only, whose error the caller shares). Writes nothing.
  OutputWriter(const CommandLine& options, const SimulationInterface& sim, const OutputSchedule& settings,
            ScenarioRun& scenario);
  OutputWriter(const OutputWriter&) = delete;
  OutputWriter& operator=(const OutputWriter&) = delete;

  /// Writes the first files, opens the tables and the frame series, and prints the run's header on `out`. If a
  /// file cannot be written, a folder this run created is removed again and an existing one is put back as it was
  /// (WriteError on every process). Collective.
  void create(const MeshCopies& copies, std::ostream& out);

  /// The output callbacks; `last` is the record of the last accepted step, which a diagnostics row reports.
  std::vector<Callback> callbacks(const StepRecord& last);

  /// Removes this run's files after bad input found only once the run was on; a run continued in its folder keeps
  /// them.
  void discard() const;
  std::filesystem::path checkpoint_file() const { return dir_ / "checkpoint.h5"; }
  /// The step of the last checkpoint this run wrote (-1: none).
  long last_checkpoint_step() const { return checkpoint_step_; }
  /// The run became unstable: from now on the checkpoint callback saves the state to unstable_state.h5 and leaves
  /// checkpoint.h5 as it was.
  void stop_unstable() { unstable_ = true; }
  /// The last line of a run stopped by an instability (UnstableStop.hpp).
  std::string unstable_stop_line() const;

 private:
  Callback diagnostics_callback(const StepRecord& last);
  Callback fields_callback();
  Callback checkpoint_callback();
  void print_header(const MeshCopies& copies, std::ostream& out) const;
  /// Runs `work` on rank 0 (nothing elsewhere); its WriteError is thrown on every process. Collective.
  void on_root(const std::function<void()>& work) const;

  const CommandLine& options_;
  const SimulationInterface& sim_;
  const Communicator& comm_;
  bool root_;
  const OutputSchedule& settings_;
  ScenarioRun& scenario_;
  std::filesystem::path dir_;
  bool restarted_, in_place_;
  int first_frame_ = 0, frame_ = 0;
  std::optional<io::OutputFolder> folder_;  ///< on rank 0
  Diagnostics diagnostics_;
  OutputTable diagnostics_table_;
  std::vector<OutputTable*> tables_;  ///< diagnostics.csv first, then the scenario's
  io::Provenance provenance_;  ///< from create() on
  std::optional<io::XdmfWriter> frames_;
  long checkpoint_step_ = -1;
  double checkpoint_time_ = 0;
  long start_step_;  ///< of the state the run began from (a restart's checkpoint)
  double start_time_;
  bool unstable_ = false, unstable_written_ = false, stale_unstable_removed_ = false;
};

}  // namespace immerse
