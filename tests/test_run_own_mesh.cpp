// `immerse run` with a membrane read from the user's own Gmsh file: the file found from the configuration's folder,
// its length unit converted by mesh.scale, a copy kept in the run folder (which then runs again as it is), and a
// separate stress-free reference mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

/// The cell of the small runs: the octahedral level-1 sphere (66 nodes) of radius 0.2, in the file's unit times `unit`.
void write_cell(const fs::path& path, double unit = 1.0, const Vec3& stretch = {1, 1, 1}) {
  write_gmsh(path, octahedral_sphere(1), {0.2 * unit * stretch.x, 0.2 * unit * stretch.y, 0.2 * unit * stretch.z});
}

/// The numbers of a diagnostics table, wall clock left out.
std::vector<std::vector<double>> numbers(const fs::path& csv) {
  std::vector<std::vector<double>> rows;
  const auto cells = without_wall_clock(read_csv(csv));
  for (std::size_t r = 1; r < cells.size(); ++r) {
    rows.emplace_back();
    for (const auto& c : cells[r]) rows.back().push_back(std::stod(c));
  }
  return rows;
}

/// Equal up to `rel` relative, or 1e-15 absolute (the nonlinear residuals are of the round-off's size).
void expect_close(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b, double rel) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t r = 0; r < a.size(); ++r) {
    ASSERT_EQ(a[r].size(), b[r].size());
    for (std::size_t c = 0; c < a[r].size(); ++c)
      EXPECT_NEAR(a[r][c], b[r][c], rel * std::abs(a[r][c]) + 1e-15) << "row " << r << ", column " << c;
  }
}

}  // namespace

// A relative mesh.file in the configuration is taken from the configuration's folder, not from the current one
// (the test program runs elsewhere); given with --set it is taken from the current folder.
TEST(OwnMesh, RelativeFileIsFoundFromTheConfigurationsFolder) {
  ScratchDir scratch("own_mesh");
  fs::create_directories(scratch / "config");
  fs::create_directories(scratch / "meshes");
  write_cell(scratch / "meshes" / "cell.msh");
  std::ofstream(scratch / "config" / "run.toml") << file_membrane_toml("../meshes/cell.msh");
  ASSERT_NE(fs::current_path(), scratch / "config");
  const auto r = run_immerse(run_args(scratch / "config" / "run.toml", scratch / "a", small_run_sets(1)), scratch / "a");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_text(scratch / "a" / "mesh_membrane0.msh"), read_text(scratch / "meshes" / "cell.msh"));

  auto sets = small_run_sets(1);
  sets.push_back("membrane[0].mesh.file=" + fs::relative(scratch / "meshes" / "cell.msh").string());
  const auto s = run_immerse(run_args(scratch / "config" / "run.toml", scratch / "b", sets), scratch / "b");
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(read_text(scratch / "b" / "mesh_membrane0.msh"), read_text(scratch / "meshes" / "cell.msh"));
}

// The same cell written in micrometres-like units (coordinates 1e6 times larger) with mesh.scale = 1e-6 runs as the
// cell in the configuration's unit: the same node positions and diagnostics.
TEST(OwnMesh, ScaledMeshRunsAsTheMeshInMetres) {
  ScratchDir scratch("own_mesh");
  write_cell(scratch / "cell_m.msh");
  write_cell(scratch / "cell_um.msh", 1e6);
  std::ofstream(scratch / "m.toml") << file_membrane_toml("cell_m.msh");
  std::ofstream(scratch / "um.toml") << file_membrane_toml("cell_um.msh", "mesh.scale = 1e-6\n");
  for (const char* name : {"m", "um"}) {
    const auto r = run_immerse(run_args(scratch / (std::string(name) + ".toml"), scratch / name, small_run_sets(2)),
                               scratch / name);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const auto a = io::Checkpoint::read(scratch / "m" / "checkpoint.h5").array("membrane[0].positions");
  const auto b = io::Checkpoint::read(scratch / "um" / "checkpoint.h5").array("membrane[0].positions");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << i;
  expect_close(numbers(scratch / "m" / "diagnostics.csv"), numbers(scratch / "um" / "diagnostics.csv"), 1e-9);
}

// The run folder holds a copy of the mesh, config.resolved.toml names it, and the folder runs again as it is: into
// another folder with the same results, and into itself (--overwrite: the copy is read before the old run's files go).
// Two membranes of one file share one copy.
TEST(OwnMesh, RunFolderKeepsTheMeshAndRunsAgain) {
  ScratchDir scratch("own_mesh");
  write_cell(scratch / "cell.msh");
  std::string two = file_membrane_toml("cell.msh");
  two.replace(two.find("center = [0.5, 0.5, 0.5]"), 24, "center = [0.3, 0.3, 0.5]");
  std::ofstream(scratch / "two.toml")
      << two << "[[membrane]]\nmesh.family = \"file\"\nmesh.file = \"cell.msh\"\ncenter = [0.7, 0.7, 0.5]\nEs = 0.1\n";
  const fs::path out = scratch / "out";
  const auto first = run_immerse(run_args(scratch / "two.toml", out, small_run_sets(2)), scratch / "first");
  ASSERT_EQ(first.status, 0) << first.err;
  EXPECT_EQ(read_text(out / "mesh_membrane0.msh"), read_text(scratch / "cell.msh"));
  EXPECT_FALSE(fs::exists(out / "mesh_membrane1.msh"));
  const std::string resolved = read_text(out / "config.resolved.toml");
  std::size_t named = 0;
  for (auto at = resolved.find("\nmesh.file = \"mesh_membrane0.msh\"\n"); at != std::string::npos;
       at = resolved.find("\nmesh.file = \"mesh_membrane0.msh\"\n", at + 1))
    ++named;
  EXPECT_EQ(named, 2u) << resolved;
  EXPECT_NE(resolved.find("# derived: the copy of " + (scratch / "cell.msh").string() + " in the run folder"),
            std::string::npos);

  const auto again = run_immerse({"run", (out / "config.resolved.toml").string(), "--out", (scratch / "again").string()},
                                 scratch / "again");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(without_wall_clock(read_csv(scratch / "again" / "diagnostics.csv")),
            without_wall_clock(read_csv(out / "diagnostics.csv")));
  EXPECT_NE(read_text(scratch / "again" / "config.resolved.toml").find("\nmesh.file = \"mesh_membrane0.msh\"\n"),
            std::string::npos);

  const auto itself = run_immerse({"run", (out / "config.resolved.toml").string(), "--out", out.string(), "--overwrite"},
                                  scratch / "itself");
  ASSERT_EQ(itself.status, 0) << itself.err;
  EXPECT_EQ(read_text(out / "mesh_membrane0.msh"), read_text(scratch / "cell.msh"));
}

// A run continued from its checkpoint with its own config.resolved.toml (naming the copy, not the original file).
TEST(OwnMesh, RunContinuesFromItsResolvedConfiguration) {
  ScratchDir scratch("own_mesh");
  write_cell(scratch / "cell.msh");
  std::ofstream(scratch / "cell.toml") << file_membrane_toml("cell.msh");
  const fs::path out = scratch / "out";
  ASSERT_EQ(run_immerse(run_args(scratch / "cell.toml", out, small_run_sets(1)), scratch / "first").status, 0);
  const auto r = run_immerse(
      run_args(out / "config.resolved.toml", out, {"time.end=0.25"}, out / "checkpoint.h5"), scratch / "again");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_csv(out / "diagnostics.csv").size(), 4u);  // header, steps 0, 1, 2
}

// A stretched initial mesh with a spherical stress-free mesh (mesh.reference_file): the membrane is stressed from
// the start and relaxes towards the sphere; with its own shape as reference it stays at rest.
TEST(OwnMesh, ReferenceFileIsTheStressFreeShape) {
  ScratchDir scratch("own_mesh");
  write_cell(scratch / "ellipsoid.msh", 1.0, {1.25, 1.1, 0.8});
  write_cell(scratch / "sphere.msh");
  std::ofstream(scratch / "relaxing.toml")
      << file_membrane_toml("ellipsoid.msh", "reference = \"file\"\nmesh.reference_file = \"sphere.msh\"\n");
  std::ofstream(scratch / "resting.toml") << file_membrane_toml("ellipsoid.msh");
  for (const char* name : {"relaxing", "resting"}) {
    const auto r = run_immerse(run_args(scratch / (std::string(name) + ".toml"), scratch / name, small_run_sets(2)),
                               scratch / name);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_EQ(read_text(scratch / "relaxing" / "mesh_membrane0_reference.msh"), read_text(scratch / "sphere.msh"));
  const auto header = read_csv(scratch / "relaxing" / "diagnostics.csv")[0];
  const auto a1 = std::size_t(std::find(header.begin(), header.end(), "a1") - header.begin());
  ASSERT_LT(a1, header.size());
  const auto relaxing = read_csv(scratch / "relaxing" / "diagnostics.csv");
  const auto resting = read_csv(scratch / "resting" / "diagnostics.csv");
  const double start = std::stod(relaxing[1][a1]);
  EXPECT_EQ(std::stod(resting[1][a1]), start);
  EXPECT_LT(std::stod(relaxing.back()[a1]), start * (1 - 1e-4));  // the long axis shortens
  EXPECT_NEAR(std::stod(resting.back()[a1]), start, 1e-9 * start);
}
