// Replays the fuzzing corpora (fuzz/corpus/config, fuzz/corpus/mesh; scripts/fuzz.sh keeps them) through the
// entry points `immerse run` uses: every file either gives a result or is refused with immerse::InputError
// whose message is one line; any other exception fails the test (under the debug preset, AddressSanitizer and
// UBSan watch the same replay). The configuration files also survive their resolved round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <typeinfo>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/membrane/GmshReader.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"

using namespace immerse;
namespace fs = std::filesystem;

namespace {

std::vector<fs::path> corpus(const std::string& name) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(IMMERSE_SOURCE_DIR) / "fuzz" / "corpus" / name))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

struct Tally {
  int accepted = 0, refused = 0;
};

// Runs `read` on every file of the corpus; counts results and one-line refusals, fails on anything else.
template <class Read>
Tally replay(const std::string& name, Read read) {
  Tally t;
  for (const auto& f : corpus(name)) {
    try {
      read(f);
      ++t.accepted;
    } catch (const InputError& e) {
      ++t.refused;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << f << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << typeid(e).name() << " instead of InputError: " << e.what();
    }
  }
  return t;
}

}  // namespace

TEST(RobustnessCorpus, ConfigurationFilesResolveOrAreRefusedWithOneLine) {
  const io::ConfigSchema schema = run_schema();
  const Tally t = replay("config", [&](const fs::path& f) {
    const io::Config c = apply_scenario(schema.parse_file(f));
    EXPECT_TRUE(schema.parse_string(c.to_toml_string(), "resolved") == c) << f;
  });
  std::cout << "config corpus: " << t.accepted << " resolved, " << t.refused << " refused\n";
  // The bundled scenarios are in the corpus and resolve; the fuzzer's inputs are mostly refused.
  EXPECT_GE(t.accepted, 10);
  EXPECT_GT(t.refused, 0);
}

TEST(RobustnessCorpus, MeshFilesReadOrAreRefusedWithOneLine) {
  const Tally t = replay("mesh", [](const fs::path& f) { read_gmsh(f.string()); });
  std::cout << "mesh corpus: " << t.accepted << " read, " << t.refused << " refused\n";
  EXPECT_GE(t.accepted, 4);  // the four octahedron seeds
  EXPECT_GT(t.refused, 0);
}
