// One-process runs reproduce, bit for bit, the state and diagnostics recorded in tests/data/one_process_states.txt:
// the threaded capsule on 44^3 cells under JFNK (two threads), and the quick red-cell channel with contact forces and
// one cell of viscosity ratio 5 under JFNK, Anderson and RK2, each a few steps of `immerse run`. The record guards the
// numbers of the one-process run while the code around them is reorganised: a change meant to alter them (a new
// scheme, a corrected formula) records new values and says why in CHANGELOG.md. Bitwise on the machine and toolchain
// that recorded them (x86-64, Debian 12's GCC 12 and FFTW 3.3.10, optimized build); a failure prints the new line.
// The state checksum is FNV-1a 64 over every checkpoint entry but the configuration text (a new key with a default
// does not change the numbers); the diagnostics checksum over diagnostics.csv without its wall-clock column.
#include <gtest/gtest.h>

#include <cinttypes>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Fnv1a64.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

struct Case {
  std::string name, scenario;
  std::vector<std::string> sets;
  int threads;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> cases() {
  auto capsule = small_membrane_sets(4);
  capsule.insert(capsule.end(), {"grid.nx=44", "grid.ny=44", "grid.nz=44", "membrane[0].mesh.level=2",
                                 "time.scheme=jfnk"});
  const auto channel = [](const std::string& scheme, int steps) {
    return std::vector<std::string>{"time.scheme=\"" + scheme + "\"", "time.dt=2e-5",
                                    "time.end=" + std::to_string(steps * 2e-5), "solver.newton_rtol=1e-11",
                                    "contact.range=1.5e-6", "membrane[0].viscosity_ratio=5.0",
                                    "output.fields_every=0"};
  };
  return {{"capsule44_jfnk", "oscillating_membrane_quick.toml", capsule, 2},
          {"channel_jfnk", "rbc_channel_quick.toml", channel("jfnk", 4), 1},
          {"channel_anderson", "rbc_channel_quick.toml", channel("anderson", 3), 1},
          {"channel_rk2", "rbc_channel_quick.toml", channel("rk2", 6), 1}};
}

std::uint64_t state_checksum(const io::Checkpoint& ck) {
  io::Checkpoint state = ck;
  state.erase("config");
  return state.checksum();
}

std::uint64_t diagnostics_checksum(const fs::path& csv) {
  io::Fnv1a64 h;
  for (const auto& row : without_wall_clock(read_csv(csv)))
    for (const auto& cell : row) h.text(cell + ",");
  return h.value();
}

std::map<std::string, std::pair<std::string, std::string>> recorded() {
  std::map<std::string, std::pair<std::string, std::string>> r;
  std::ifstream in(fs::path(IMMERSE_SOURCE_DIR) / "tests" / "data" / "one_process_states.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string name, state, diagnostics;
    s >> name >> state >> diagnostics;
    r[name] = {state, diagnostics};
  }
  return r;
}

std::string hex(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016" PRIx64, v);
  return b;
}

class Frozen : public ::testing::TestWithParam<Case> {};

TEST_P(Frozen, OneProcessRunReproducesTheRecordedStateAndDiagnostics) {
  const Case& c = GetParam();
  ScratchDir dir("frozen_" + c.name);
  const fs::path out = dir / "run";
  const auto r = run_immerse(run_args(scenario_file(c.scenario), out, c.sets), dir / "log",
                             {"OMP_NUM_THREADS=" + std::to_string(c.threads)});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto ck = io::Checkpoint::read(out / "checkpoint.h5");
  const std::string state = hex(state_checksum(ck)), diagnostics = hex(diagnostics_checksum(out / "diagnostics.csv"));
  const auto all = recorded();
  const auto it = all.find(c.name);
  ASSERT_NE(it, all.end()) << "no record of " << c.name << "; its line: " << c.name << " " << state << " "
                           << diagnostics;
  EXPECT_EQ(state, it->second.first) << "state of step " << ck.get_int("step") << "; new line: " << c.name << " "
                                     << state << " " << diagnostics;
  EXPECT_EQ(diagnostics, it->second.second) << "new line: " << c.name << " " << state << " " << diagnostics;
}

INSTANTIATE_TEST_SUITE_P(Runs, Frozen, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

}  // namespace
