#include "immerse/simulation/StepTimings.hpp"

#include <cstdio>
#include <utility>

namespace immerse {

std::string StepTimings::profile(double wall_seconds, long steps) const {
  const std::pair<const char*, double> parts[] = {{"membrane forces", force},
                                                  {"contact", contact},
                                                  {"spreading", spread},
                                                  {"fluid", fluid},
                                                  {"interpolation", interpolate},
                                                  {"the rest", wall_seconds - total()}};
  std::string s = "ms per step (% of the wall time):";
  for (const auto& [name, seconds] : parts) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " %s %.1f (%.0f %%)%s", name, 1e3 * seconds / double(steps),
                  100 * seconds / wall_seconds, name == parts[5].first ? "" : ",");
    s += buf;
  }
  return s;
}

}  // namespace immerse
