#include "immerse/run/UnstableStop.hpp"

#include <initializer_list>
#include <sstream>
#include <vector>

#include "immerse/io/Provenance.hpp"
#include "immerse/io/TomlFormat.hpp"

namespace immerse {

namespace {

std::string key_of(const std::string& set) {
  std::string key = set.substr(0, set.find('='));
  const auto first = key.find_first_not_of(" \t"), last = key.find_last_not_of(" \t");
  return first == std::string::npos ? std::string() : key.substr(first, last - first + 1);
}

// The command line of `immerse run` that continues from `kept` (or starts again) with `step_key` = `step_value`,
// every other argument as the user gave it.
std::string continue_command(const CommandLine& options, const KeptCheckpoint& kept, const std::string& step_key,
                             const std::string& step_value, int processes) {
  std::vector<std::string> args;
  const auto add = [&](std::initializer_list<std::string> words) { args.insert(args.end(), words); };
  if (processes > 1) add({"mpiexec", "-n", std::to_string(processes)});
  add({options.program, "run", options.file.string(), "--out", options.out.string()});
  for (const auto& set : options.sets)
    if (const std::string key = key_of(set); key != "time.dt" && key != "scenario.k_dt") add({"--set", set});
  if (options.verbose) add({"--verbose"});
  if (!kept.in_out || kept.file.empty()) add({"--overwrite"});  // the failed run's files go
  if (!kept.file.empty()) add({"--restart", kept.file.string()});
  add({"--set", step_key + "=" + step_value});
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  return io::Provenance::quote_command_line(static_cast<int>(argv.size()), argv.data());
}

}  // namespace

std::string unstable_stop_line(const CommandLine& options, const io::Config& config, const KeptCheckpoint& kept,
                               long step, bool unstable_written, int processes) {
  const std::string key = config.derivation("time.dt").empty() ? "time.dt" : "scenario.k_dt";
  const std::string half = io::format_number(config.get<double>(key) / 2);
  std::ostringstream s;
  s.precision(10);
  s << "immerse: ";
  if (kept.file.empty())
    s << "no checkpoint kept: none was written before step " << step << " (output.checkpoint_every = "
      << config.value_text("output.checkpoint_every") << ")";
  else
    s << (kept.in_out ? "kept the last good checkpoint " : "no checkpoint of this run; it began from ")
      << kept.file.string() << " (step " << kept.step << ", t = " << kept.time << ")";
  if (unstable_written) s << "; the state of step " << step << " is in " << unstable_state_file(options.out).string();
  s << "; " << (kept.file.empty() ? "start again" : "continue") << " with half the step: "
    << continue_command(options, kept, key, half, processes) << "\n";
  return s.str();
}

}  // namespace immerse
