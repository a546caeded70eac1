// `immerse run` on bad input: the real program exits with status 2 and one line on stderr naming the parameter,
// the value given and what is allowed, before anything is written (the --out folder is not even created).
#include <gtest/gtest.h>

#include <cstring>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

struct BadInput {
  std::string name;
  std::string file;               ///< a file of the suite folder, or "" for oscillating_membrane_quick.toml
  std::vector<std::string> sets;  ///< added to small_membrane_sets(1)
  std::string restart;            ///< a checkpoint of the suite folder, or ""
  std::string message;            ///< expected in the one line on stderr
};

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

class BadInputTest : public ::testing::TestWithParam<BadInput> {
 public:
  static fs::path suite_dir() { return fs::temp_directory_path() / ("immerse_bad_input_" + std::to_string(getpid())); }

  // A valid checkpoint (one step of the small run), damaged copies of it, and hand-written bad configurations.
  static void SetUpTestSuite() {
    const fs::path dir = suite_dir();
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "good",
                                        small_membrane_sets(1)),
                               dir / "good_run");
    ASSERT_EQ(r.status, 0) << r.err;
    const fs::path ck = dir / "good" / "checkpoint.h5";
    ASSERT_TRUE(fs::exists(ck));

    // Flip the lowest bit of the first stored membrane coordinate: the file stays valid HDF5, the data differ.
    const double x0 = io::Checkpoint::read(ck).array("membrane[0].positions")[0];
    std::string bytes = read_text(ck);
    const auto at = bytes.find(std::string(reinterpret_cast<const char*>(&x0), sizeof x0));
    ASSERT_NE(at, std::string::npos);
    bytes[at] = static_cast<char>(bytes[at] ^ 1);
    std::ofstream(dir / "flipped.h5", std::ios::binary) << bytes;
    const std::string whole = read_text(ck);
    std::ofstream(dir / "truncated.h5", std::ios::binary) << whole.substr(0, whole.size() / 2);

    // The quick scenario with its [[membrane]] table repeated: two membranes at the same centre.
    const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
    std::ofstream(dir / "two_membranes.toml") << base << "\n" << base.substr(base.find("[[membrane]]"));
    std::ofstream(dir / "syntax_error.toml") << "[fluid]\nmu = = 1\n";
  }
  static void TearDownTestSuite() { fs::remove_all(suite_dir()); }
};

TEST_P(BadInputTest, ExitsWithStatus2AndOneLineBeforeWritingAnything) {
  const BadInput& b = GetParam();
  ScratchDir scratch("bad_input");
  const fs::path out = scratch / "out";
  const fs::path file = b.file.empty() ? scenario_file("oscillating_membrane_quick.toml") : suite_dir() / b.file;
  auto sets = small_membrane_sets(1);
  sets.insert(sets.end(), b.sets.begin(), b.sets.end());
  const auto r = run_immerse(run_args(file, out, sets, b.restart.empty() ? fs::path{} : suite_dir() / b.restart),
                             scratch / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(b.message), std::string::npos) << "expected: " << b.message << "\ngot: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "the output folder was created before the input was checked";
}

INSTANTIATE_TEST_SUITE_P(
    Run, BadInputTest,
    ::testing::Values(
        BadInput{"unknown_key", "", {"fluid.muu=1"}, "", "unknown key fluid.muu (did you mean fluid.mu?)"},
        BadInput{"wrong_type", "", {"fluid.mu=\"thick\""}, "", "fluid.mu = \"thick\": must be a finite number > 0"},
        BadInput{"out_of_range", "", {"fluid.mu=-1"}, "", "fluid.mu = -1: must be a finite number > 0"},
        BadInput{"not_a_number", "", {"fluid.mu=nan"}, "", "fluid.mu = nan: must be a finite number > 0"},
        BadInput{"one_cell", "", {"grid.nx=1"}, "", "grid.nx = 1: must be an integer >= 2"},
        BadInput{"non_cubic_cells", "", {"grid.nz=8"}, "",
                 "grid: cells must be cubic, but Lx/nx = 0.0625 and Lz/nz = 0.125"},
        BadInput{"membrane_outside", "", {"membrane[0].center=[1.5,0.5,0.5]"}, "",
                 "membrane[0] lies outside the box: node 0 at (1.75, 0.5, 0.5) is outside the fluid domain: beyond the "
                 "wall x = 1"},
        BadInput{"membrane_at_wall", "", {"membrane[0].center=[0.28,0.5,0.5]"}, "",
                 "membrane[0] comes within 0.03 m of a wall: must keep at least one cell (0.0625 m) clear"},
        BadInput{"overlapping_membranes", "two_membranes.toml", {"membrane[1].mesh.level=1"}, "",
                 "membrane[1] overlaps or touches membrane[0]: its node"},
        BadInput{"nested_membranes", "two_membranes.toml",
                 {"membrane[1].mesh.level=1", "membrane[1].shape=\"sphere\"", "membrane[1].radius=0.05"}, "",
                 "membrane[1] lies inside membrane[0]"},
        BadInput{"unknown_scheme", "", {"time.scheme=\"rk4\""}, "", "time.scheme = \"rk4\": must be one of"},
        BadInput{"dense_bfgs_on_a_large_mesh", "", {"time.scheme=\"bfgs\"", "membrane[0].mesh.level=4"}, "",
                 "is limited to 12000 unknowns and this run has 12294"},
        BadInput{"missing_config", "no_such_file.toml", {}, "", "no_such_file.toml: cannot read: No such file or directory"},
        BadInput{"config_syntax_error", "syntax_error.toml", {}, "", "syntax_error.toml:2"},
        BadInput{"missing_mesh_file", "", {"membrane[0].mesh.family=\"file\"", "membrane[0].mesh.file=\"no_such.msh\""},
                 "", "membrane[0].mesh no_such.msh: cannot open the file"},
        BadInput{"checkpoint_of_other_grid", "", {"grid.nx=8", "grid.ny=8", "grid.nz=8"}, "good/checkpoint.h5",
                 "checkpoint was written by a different configuration: it has '[grid] nx = 16', this run has "
                 "'[grid] nx = 8'"},
        BadInput{"corrupted_checkpoint", "", {}, "flipped.h5", "flipped.h5 is corrupted: checksum mismatch"},
        BadInput{"truncated_checkpoint", "", {}, "truncated.h5", "truncated.h5 is truncated or not an HDF5 file"},
        BadInput{"missing_checkpoint", "", {}, "no_such_checkpoint.h5", "no_such_checkpoint.h5"}),
    [](const auto& p) { return p.param.name; });

}  // namespace

// A user's mesh file that changed between a run and its restart: the reference state rebuilt from the configuration
// is not the one in the checkpoint, and the restart is refused.
TEST(BadInputRestart, ChangedMeshFileIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("immerse_changed_mesh_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Mesh sphere = octahedral_sphere(1);
  auto write_msh = [&](double radius) {
    std::ofstream f(dir / "cell.msh");
    f.precision(17);
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << sphere.nodes.size() << "\n";
    for (std::size_t i = 0; i < sphere.nodes.size(); ++i)
      f << i + 1 << " " << radius * sphere.nodes[i].x << " " << radius * sphere.nodes[i].y << " "
        << radius * sphere.nodes[i].z << "\n";
    f << "$EndNodes\n$Elements\n" << sphere.elements.size() << "\n";
    for (std::size_t e = 0; e < sphere.elements.size(); ++e) {
      f << e + 1 << " 9 2 0 1";
      for (int n : sphere.elements[e]) f << " " << n + 1;
      f << "\n";
    }
    f << "$EndElements\n";
  };
  auto sets = [&](int steps) {
    auto s = small_membrane_sets(steps);
    s.insert(s.end(), {"membrane[0].mesh.family=\"file\"", "membrane[0].mesh.file=\"" + (dir / "cell.msh").string() + "\"",
                       "membrane[0].reference=\"initial\""});
    return s;
  };
  write_msh(0.2);
  const auto first = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "a", sets(1)),
                                 dir / "first");
  ASSERT_EQ(first.status, 0) << first.err;
  write_msh(0.21);
  const auto again = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "a", sets(2),
                                          dir / "a" / "checkpoint.h5"),
                                 dir / "again");
  EXPECT_EQ(again.status, 2) << again.err;
  EXPECT_NE(again.err.find("the reference state of membrane[0] differs"), std::string::npos) << again.err;
  fs::remove_all(dir);
}
