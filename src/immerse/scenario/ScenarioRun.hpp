#pragma once
// What a scenario kind adds to a run besides the fluid and the membranes: columns of diagnostics.csv, tables of its
// own, work after each step and its state in the checkpoints. This base adds nothing (the shear scenarios, custom);
// make_scenario_run picks the kind's own.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/run/Column.hpp"

namespace immerse {

class OutputTable;
class SimulationInterface;

class ScenarioRun {
 public:
  ScenarioRun() = default;
  ScenarioRun(const ScenarioRun&) = delete;
  ScenarioRun& operator=(const ScenarioRun&) = delete;
  virtual ~ScenarioRun() = default;

  /// Columns of diagnostics.csv after each membrane's own columns, and after those of all membranes.
  virtual std::vector<Column> membrane_columns() const { return {}; }
  virtual std::vector<Column> run_columns() const { return {}; }
  /// Appends the values of membrane_columns() for a membrane at positions X, and those of run_columns().
  virtual void add_membrane_values(const std::vector<Vec3>& /*X*/, std::vector<double>& /*row*/) const {}
  virtual void add_run_values(const SimulationInterface& /*sim*/, std::vector<double>& /*row*/) const {}

  /// Binds the scenario to the built simulation, before a restart restores it (InputError on input it cannot run).
  virtual void attach(SimulationInterface& /*sim*/) {}
  /// Starts the scenario's own state at the start of a run, or continues it from a checkpoint written by save().
  virtual void start(SimulationInterface& /*sim*/) {}
  virtual void restore(const io::Checkpoint& /*ck*/, SimulationInterface& /*sim*/) {}
  virtual void save(io::Checkpoint& /*ck*/) const {}

  /// The tables it writes besides diagnostics.csv.
  virtual std::vector<OutputTable*> tables() { return {}; }
  /// Runs after each accepted step, before the step's callbacks, so that a checkpoint of the step holds its effect.
  virtual void after_step(SimulationInterface& /*sim*/, const std::function<void(const std::string&)>& /*log*/,
                          std::ostream& /*out*/) {}
  /// True once the scenario has nothing left to do: the run ends before time.end.
  virtual bool done() const { return false; }
  /// Log lines: once the output is open, and when the run reached time.end before done().
  virtual void announce(std::ostream& /*out*/) const {}
  virtual void report_unfinished(std::ostream& /*out*/, const std::filesystem::path& /*checkpoint*/) const {}
};

/// The ScenarioRun of the configuration's scenario.kind.
std::unique_ptr<ScenarioRun> make_scenario_run(const io::Config& config);

}  // namespace immerse
