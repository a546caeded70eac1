#pragma once
// Every key of a run's configuration, declared once with its default, allowed range and doc string (SI units).
// `immerse run --help-config` prints it; scenario files under scenarios/ set what differs from the defaults.
#include <string>

#include "immerse/io/Config.hpp"
#include "immerse/io/ConfigSchema.hpp"

namespace immerse {

io::ConfigSchema run_schema();

/// Whether scenario.kind names one of the shear scenarios (capsule_shear, oblate_shear, bending_shear).
bool is_shear_kind(const std::string& kind);

/// Why key `key` of the [[membrane]] entry `m` does not apply to it (e.g. mesh.level with mesh.family = "file"), or
/// "" when it applies; `shear`: the run is a shear scenario (radius then sets its groups).
std::string membrane_key_not_applying(const io::Config& m, const std::string& key, bool shear);

/// Why key `key` of the [[wall]] entry `w` does not apply to it (e.g. radius with shape = "surface"), or "" when it
/// applies.
std::string wall_key_not_applying(const io::Config& w, const std::string& key);

/// Marks the keys of each [[membrane]] and [[wall]] entry that do not apply to it as left out (io::Config::leave_out).
void leave_out_inapplicable(io::Config& config);

}  // namespace immerse
