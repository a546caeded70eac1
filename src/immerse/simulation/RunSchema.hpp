#pragma once
// Every key of a run's configuration, declared once with its default, allowed range and doc string (SI units).
// `immerse run --help-config` prints it; scenario files under scenarios/ set what differs from the defaults.
#include "immerse/io/ConfigSchema.hpp"

namespace immerse {

io::ConfigSchema run_schema();

}  // namespace immerse
