#include "immerse/run/OutputWriter.hpp"

#include <algorithm>
#include <ostream>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/run/UnstableStop.hpp"

namespace immerse {

namespace {

bool same_folder(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a.parent_path().empty() ? "." : a.parent_path(), b, ec) && !ec;
}

// Whether the run continues the one in its folder (--restart of a checkpoint there); --overwrite would remove it.
bool continues_in_place(const CommandLine& options) {
  const bool in_place = !options.restart.empty() && same_folder(options.restart, options.out);
  if (in_place && options.overwrite)
    throw InputError("--overwrite: would remove the run that --restart " + options.restart.string() +
                     " continues (leave out --overwrite to continue it in " + options.out.string() + ")");
  return in_place;
}

// "KEY = VALUE (how)" for every key a scenario kind derived, the membranes' keys as membrane[i].KEY.
std::vector<std::string> derived_values(const io::Config& config) {
  std::vector<std::string> lines;
  const auto line = [](const std::string& name, const std::string& value, const std::string& how) {
    return name + " = " + value + " (" + how + ")";
  };
  for (const auto& k : config.schema().keys())
    if (const std::string how = config.derivation(k.key); !how.empty())
      lines.push_back(line(k.key, config.value_text(k.key), how));
  // Entries of a table array derived alike (the cells of a channel) print as one line per key over a run of indices:
  // t[a..b].key = value when every value is the same, else the count of values (they are in config.resolved.toml).
  for (const auto& t : config.schema().table_arrays()) {
    const std::size_t n = config.count(t.name);
    if (n == 0) continue;
    for (const auto& k : config.entry(t.name, 0).schema().keys()) {
      const auto name = [&](std::size_t i) { return t.name + "[" + std::to_string(i) + "]"; };
      for (std::size_t a = 0; a < n;) {
        const io::Config& first = config.entry(t.name, a);
        const std::string how = first.derivation(k.key);
        std::size_t b = a + 1;
        bool same = true;
        while (b < n && !how.empty() && config.entry(t.name, b).derivation(k.key) == how) {
          same = same && config.entry(t.name, b).value_text(k.key) == first.value_text(k.key);
          ++b;
        }
        if (how.empty()) {
        } else if (b - a < 3) {
          for (std::size_t i = a; i < b; ++i)
            lines.push_back(line(name(i) + "." + k.key, config.entry(t.name, i).value_text(k.key), how));
        } else {
          const std::string range = t.name + "[" + std::to_string(a) + ".." + std::to_string(b - 1) + "]." + k.key;
          lines.push_back(same ? line(range, first.value_text(k.key), how)
                               : range + ": " + std::to_string(b - a) + " values, in config.resolved.toml (" + how + ")");
        }
        a = b;
      }
    }
  }
  return lines;
}

}  // namespace

// A restart in place continues the tables after the checkpoint (a damaged table is refused before anything is
// rewritten) and the frame series after the checkpoint's frame.
OutputWriter::OutputWriter(const CommandLine& options, const SimulationInterface& sim, const OutputSchedule& settings,
                     ScenarioRun& scenario)
    : options_(options),
      sim_(sim),
      comm_(sim.communicator()),
      root_(comm_.rank() == 0),
      settings_(settings),
      scenario_(scenario),
      dir_(options.out),
      restarted_(!options.restart.empty()),
      in_place_(continues_in_place(options)),
      first_frame_(in_place_ && settings.fields_every > 0 ? static_cast<int>(sim.step() / settings.fields_every) + 1
                                                          : 0),
      frame_(first_frame_),
      diagnostics_(sim.config(), sim.num_membranes(), scenario),
      diagnostics_table_("diagnostics", diagnostics_.columns(),
                         [this](long, double step) { return step <= double(sim_.step()); }),
      start_step_(sim.step()),
      start_time_(sim.time()) {
  tables_.push_back(&diagnostics_table_);
  for (OutputTable* t : scenario.tables()) tables_.push_back(t);
  if (!root_) return;
  folder_.emplace(dir_);
  if (const auto found = folder_->run_files(); !found.empty() && !in_place_ && !options.overwrite) {
    std::string names;
    for (std::size_t i = 0; i < std::min<std::size_t>(found.size(), 3); ++i) names += (i ? ", " : "") + found[i];
    if (found.size() > 3) names += ", ...";
    throw InputError("--out " + dir_.string() + " holds another run (" + names + "): choose another folder, " +
                     (restarted_ ? std::string("restart from that run's own checkpoint")
                                 : "continue it with --restart " + checkpoint_file().string()) +
                     ", or replace it with --overwrite");
  }
  if (in_place_)
    for (OutputTable* t : tables_) t->read_kept_rows(dir_);
}

void OutputWriter::create(const MeshCopies& copies, std::ostream& out) {
  provenance_ = io::Provenance::now(
      options_.command_line.empty() ? "immerse run " + options_.file.string() : options_.command_line,
      sim_.thread_policy());
  if (restarted_)
    provenance_.restarted_from = options_.restart.string() + " at step " + std::to_string(sim_.step()) + ", t = " +
                                 io::format_number(sim_.time()) + (in_place_ ? " (continued)" : " (branched)");
  // Rank 0's host and start time on every process: attributes that the processes write together must be equal.
  for (std::string* s : {&provenance_.version, &provenance_.commit, &provenance_.command_line, &provenance_.start_time,
                         &provenance_.host, &provenance_.threads, &provenance_.restarted_from})
    *s = broadcast_text(comm_, *s);
  on_root([&] {
    folder_->keep_run_files();  // until the first files are written: a failure leaves the folder as it was
    try {
      frames_.emplace(dir_, first_frame_);  // a restart reads back the frames before the checkpoint first
      frames_->set_attributes(provenance_.attributes());
      if (options_.overwrite) folder_->remove_run_files();
      folder_->remove_temporaries();  // of a writer that was killed
      for (const OutputTable* t : tables_) t->write_kept_rows(dir_);
      print_header(copies, out);
      io::AtomicFile::write(dir_ / "config.resolved.toml",
                            provenance_.toml_comments() + copies.config.to_toml_string());
      for (const auto& [name, content] : copies.files) io::AtomicFile::write(dir_ / name, content);
      for (const OutputTable* t : tables_) t->write_column_table(dir_);
      const auto mode = in_place_ ? io::CsvWriter::Mode::Append : io::CsvWriter::Mode::Create;
      for (OutputTable* t : tables_) t->open(dir_, mode);
    } catch (const WriteError&) {
      folder_->restore_kept();
      throw;
    }
    folder_->drop_kept();
  });
}

void OutputWriter::on_root(const std::function<void()>& work) const {
  std::string failed;
  if (root_) try {
      work();
    } catch (const WriteError& e) {
      failed = e.what();
    }
  if (const std::string first = first_error(comm_, failed); !first.empty()) throw WriteError(first);
}

void OutputWriter::print_header(const MeshCopies& copies, std::ostream& out) const {
  out << "# immerse " << provenance_.version << " (commit " << provenance_.commit << "): " << options_.file.string()
      << " -> " << dir_.string() << "\n";
  for (const auto& line : derived_values(copies.config)) out << "# derived: " << line << "\n";
  if (!sim_.packing_summary().empty()) out << "# " << sim_.packing_summary() << "\n";
  if (const std::string d = sim_.decomposition_summary(); !d.empty()) out << "# " << d << "\n";
  if (options_.verbose)
    out << "# resolved configuration (saved as config.resolved.toml)\n" << copies.config.to_toml_string();
  out << std::flush;
}

// The restart step's row, frame and checkpoint exist (continued in place) or are not needed (branched).
std::vector<Callback> OutputWriter::callbacks(const StepRecord& last) {
  std::vector<Callback> callbacks{diagnostics_callback(last), fields_callback(), checkpoint_callback()};
  for (auto& c : callbacks)
    if (restarted_ && (in_place_ || !c.at_start)) c.last_step = sim_.step();
  return callbacks;
}

// A row needs the record of its step: the step that turned out unstable has none.
Callback OutputWriter::diagnostics_callback(const StepRecord& last) {
  return {"diagnostics", settings_.diagnostics_every, !in_place_, true, [this, &last](const SimulationInterface& s) {
            if (last.step != s.step()) return;
            const std::vector<double> row = diagnostics_.row(s, last);
            on_root([&] { diagnostics_table_.row(row); });
          }};
}

Callback OutputWriter::fields_callback() {
  const bool on = settings_.fields_every > 0;
  return {"fields", settings_.fields_every, !in_place_ && on, on,
          [this](const SimulationInterface& s) {
            s.write_frame(root_ ? &*frames_ : nullptr, dir_, frame_, provenance_.attributes(), settings_.fluid_fields);
            ++frame_;
          }};
}

// A checkpoint is newer than the unstable state of an attempt this run continues: that post-mortem file goes.
Callback OutputWriter::checkpoint_callback() {
  return {"checkpoint", settings_.checkpoint_every, false, true, [this](const SimulationInterface& s) {
            const auto scenario_state = [this](io::Checkpoint& ck) { scenario_.save(ck); };
            if (unstable_) {
              s.write_checkpoint(unstable_state_file(dir_), provenance_.attributes(), scenario_state);
              unstable_written_ = true;
              return;
            }
            s.write_checkpoint(checkpoint_file(), provenance_.attributes(), scenario_state);
            checkpoint_step_ = s.step();
            checkpoint_time_ = s.time();
            if (!stale_unstable_removed_) {
              on_root([&] {
                std::error_code ec;
                std::filesystem::remove(unstable_state_file(dir_), ec);
                if (ec) throw WriteError("cannot remove " + unstable_state_file(dir_).string() + ": " + ec.message());
              });
              stale_unstable_removed_ = true;
            }
          }};
}

std::string OutputWriter::unstable_stop_line() const {
  KeptCheckpoint kept;
  if (checkpoint_step_ >= 0)
    kept = {checkpoint_file(), checkpoint_step_, checkpoint_time_, true};
  else if (restarted_)
    kept = {options_.restart, start_step_, start_time_, in_place_};
  return immerse::unstable_stop_line(options_, sim_.config(), kept, sim_.step(), unstable_written_, comm_.size());
}

void OutputWriter::discard() const {
  if (root_ && !in_place_) folder_->remove_run_files();
}

}  // namespace immerse
