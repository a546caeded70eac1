#include "immerse/run/TimeLoop.hpp"

#include <chrono>
#include <ostream>

#include "immerse/parallel/Agreement.hpp"
#include "immerse/run/StopSignals.hpp"

namespace immerse {

namespace {

// The record the first row of a series reports: the initial state, or the checkpoint's step after a restart.
StepRecord record_of_start(const SimulationInterface& sim) {
  StepRecord r;
  r.step = sim.step();
  r.time = sim.time();
  return r;
}

}  // namespace

TimeLoop::TimeLoop(SimulationInterface& sim, ScenarioRun& scenario, OutputWriter& output, const OutputSchedule& settings,
                   std::ostream& out, std::ostream& err)
    : sim_(sim),
      scenario_(scenario),
      output_(output),
      out_(out),
      err_(err),
      last_(record_of_start(sim)),
      callbacks_(output.callbacks(last_)),
      progress_(out, settings.end_time, settings.log_seconds),
      timings_at_start_(sim.timings()) {}

bool TimeLoop::stop_signal() {
  signal_ = max_over_processes(sim_.communicator(), StopSignals::received());
  return signal_ != 0;
}

int TimeLoop::run() {
  try {
    for (auto& c : callbacks_)
      if (c.at_start) c.run(sim_, sim_.step());
    if (stop_signal()) status_ = 4;
    while (status_ == 0 && !sim_.finished() && !scenario_.done()) step_once();
    if (status_ == 0) scenario_.report_unfinished(out_, output_.checkpoint_file());
  } catch (const SimulationError& e) {
    progress_.finish();
    err_ << "immerse: run stopped: " << e.what() << "\n";
    status_ = 3;
    output_.stop_unstable();
  } catch (const StopRequested&) {
    status_ = 4;  // while a rejected step was to be retried: the state is the last accepted step's
    stop_signal();
  } catch (const WriteError& e) {
    write_failed(e);
  } catch (const InputError&) {
    // A PETSc option no solver object used in the first solve, say: exit 2 as if found before writing, so this run's
    // files go again; a restart in its checkpoint's folder keeps them.
    progress_.finish();
    output_.discard();
    throw;
  }
  progress_.finish();
  // A failure to save the last state is a failed write too (exit 5). A last state the membranes cannot be evaluated
  // in (an element that a volume correction turned over, say) loses the output that needs its forces, not the rest:
  // it is saved as the unstable state and the run counts as stopped by the numerics (exit 3).
  if (status_ != 5) try {
      for (auto& c : callbacks_) {
        if (!c.at_end || c.last_step == sim_.step()) continue;
        try {
          c.run(sim_, sim_.step());
        } catch (const SimulationError& e) {
          err_ << "immerse: " << c.name << " of step " << sim_.step() << " not written: " << e.what() << "\n";
          status_ = 3;
          output_.stop_unstable();
        }
      }
    } catch (const WriteError& e) {
      write_failed(e);
    }
  if (status_ == 3) err_ << output_.unstable_stop_line();
  if (status_ == 4)
    err_ << "immerse: interrupted by signal " << signal_ << " at step " << sim_.step() << ", t = "
         << sim_.time() << "; checkpoint written to " << output_.checkpoint_file().string() << "\n";
  return status_;
}

// The scenario's work comes within the step, before its callbacks, so that a checkpoint of the step holds it.
void TimeLoop::step_once() {
  const auto t0 = std::chrono::steady_clock::now();
  const auto add_time = [&] {
    stepping_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  try {
    last_ = sim_.advance([this](const std::string& message) { log(message); },
                         [] { return StopSignals::received() != 0; });
  } catch (...) {
    add_time();
    throw;
  }
  add_time();
  ++steps_;
  scenario_.after_step(sim_, [this](const std::string& message) { log(message); }, out_);
  for (auto& c : callbacks_)
    if (c.due(sim_.step())) c.run(sim_, sim_.step());
  progress_.update(sim_, steps_);
  if (stop_signal()) status_ = 4;
}

void TimeLoop::log(const std::string& message) { out_ << "\n" << message << "\n" << std::flush; }

// A full disk or a folder gone: no further write is attempted; what was written before is complete.
void TimeLoop::write_failed(const WriteError& e) {
  progress_.finish();
  const long ck = output_.last_checkpoint_step();
  err_ << "immerse: run stopped at step " << sim_.step() << ", t = " << sim_.time() << ": " << e.what() << " ("
       << (ck >= 0 ? "last checkpoint written: step " + std::to_string(ck) : std::string("no checkpoint written"))
       << ")\n";
  status_ = 5;
}

}  // namespace immerse
