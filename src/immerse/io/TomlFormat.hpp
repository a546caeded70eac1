#pragma once
// Formatting of configuration values as TOML text (shared by Config and ConfigSchema).
#include <string>

#include "immerse/io/ConfigSchema.hpp"

namespace immerse::io {

/// Shortest text that reads back to the same double ("0.001", "1e-20", "2").
std::string format_number(double v);
/// A TOML value: floats always carry a '.' or exponent, strings are quoted and escaped.
std::string format_toml(const ConfigValue& v);

}  // namespace immerse::io
