#include "immerse/simulation/CheckpointEntries.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/simulation/Parameters.hpp"

namespace immerse {

void check_checkpoint_configuration(const io::Config& config, const io::Checkpoint& ck) {
  // The names of mesh files (and of walls' surface files) may differ: a run folder's copy stands for its original (what
  // the files hold is compared with the reference state by the restore).
  io::Config theirs = config.schema().parse_string(ck.get_string("config"), "checkpoint");
  leave_out_inapplicable(theirs);
  const auto may_change = [](const std::string& key) {
    return key == "time.end" || key == "scenario.kt_end" || key == "time.dt" || key == "scenario.k_dt" ||
           key == "time.dt_min" || key.starts_with("output.") || key.starts_with("solver.") || key == "mesh.file" ||
           key == "mesh.reference_file" || key == "file";
  };
  const auto differ = [&](const std::string& key, const std::string& was, const std::string& is) {
    throw InputError(key + " = " + is + ": the checkpoint " + ck.source() + " was written with " + key + " = " + was +
                     " (on restart only time.end, time.dt, time.dt_min, scenario.kt_end, scenario.k_dt, [output] and "
                     "[solver] keys may change)");
  };
  for (const auto& k : config.schema().keys())
    if (!may_change(k.key) && theirs.value_text(k.key) != config.value_text(k.key))
      differ(k.key, theirs.value_text(k.key), config.value_text(k.key));
  for (const auto& t : config.schema().table_arrays()) {
    if (theirs.count(t.name) != config.count(t.name))
      differ("[[" + t.name + "]] count", std::to_string(theirs.count(t.name)), std::to_string(config.count(t.name)));
    for (std::size_t i = 0; i < config.count(t.name); ++i)
      for (const auto& k : config.entry(t.name, i).schema().keys()) {
        if (may_change(k.key)) continue;
        const std::string was = theirs.entry(t.name, i).value_text(k.key),
                          is = config.entry(t.name, i).value_text(k.key);
        if (was != is) differ(t.name + "[" + std::to_string(i) + "]." + k.key, was, is);
      }
  }
}

double continued_step(const io::Config& config, const io::Checkpoint& ck) {
  const io::Config theirs = config.schema().parse_string(ck.get_string("config"), "checkpoint");
  const double dt = ck.get_double("stepper.dt");
  CheckpointEntries(ck).number("stepper.dt", dt, std::isfinite(dt) && dt > 0 && dt <= theirs.get<double>("time.dt"),
                               "in (0, time.dt]");
  return std::min(dt, config.get<double>("time.dt"));
}

double CheckpointEntries::number(const std::string& name, double v, bool ok, const std::string& allowed) const {
  if (ok) return v;
  std::ostringstream s;
  s << "= " << v << ": must be " << allowed;
  ck_.invalid(name, s.str());
}

std::int64_t CheckpointEntries::count(const std::string& name) const {
  const std::int64_t v = ck_.get_int(name);
  number(name, double(v), v >= 0, "an integer >= 0");
  return v;
}

double CheckpointEntries::time_value(const std::string& name) const {
  const double v = ck_.get_double(name);
  return number(name, v, std::isfinite(v) && v >= 0, "a finite number >= 0");
}

const std::vector<double>& CheckpointEntries::array(const std::string& name, std::size_t size) const {
  const auto& values = ck_.array(name);
  if (values.size() != size)
    ck_.invalid(name,
                "has " + std::to_string(values.size()) + " values, this configuration needs " + std::to_string(size));
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      ck_.invalid(name, "has a value that is not finite (index " + std::to_string(i) + ")");
  return values;
}

}  // namespace immerse
