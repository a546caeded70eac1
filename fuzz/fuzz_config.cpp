// libFuzzer target: TOML text -> resolved run configuration, the path of `immerse run FILE.toml` before the
// simulation is built (ConfigSchema::parse_string with the run schema: syntax, unknown keys, types, ranges,
// repeated tables; then apply_scenario, which derives dimensional values and re-checks them).
// Accepted outcomes: a Config that survives its own round trip (to_toml_string parsed again gives an equal
// Config, as config.resolved.toml and restarts rely on), or an InputError whose message is one line.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "immerse/core/Error.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_config: %s: %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const immerse::io::ConfigSchema schema = immerse::run_schema();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const immerse::io::Config config = immerse::apply_scenario(schema.parse_string(text, "fuzz.toml"));
    const std::string resolved = config.to_toml_string();
    try {
      if (!(schema.parse_string(resolved, "resolved.toml") == config)) finding("round trip differs", resolved);
    } catch (const immerse::InputError& e) {
      finding("resolved configuration does not parse again", e.what());
    }
  } catch (const immerse::InputError& e) {
    if (std::strchr(e.what(), '\n')) finding("multi-line message", e.what());
  }
  return 0;
}
