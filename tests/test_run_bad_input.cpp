// `immerse run` on bad input: the real program exits with status 2 and one line on stderr naming the parameter,
// the value given and what is allowed, before anything is written (the --out folder is not even created). The one
// exception, a PETSc option that no solver object used, shows after the first solve: the folder is removed again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <sys/resource.h>

#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

struct BadInput {
  BadInput(std::string n, std::string f, std::vector<std::string> s, std::string r, std::string m,
           std::vector<std::string> a = {})
      : name(std::move(n)), file(std::move(f)), sets(std::move(s)), restart(std::move(r)), message(std::move(m)),
        args(std::move(a)) {}
  std::string name;
  std::string file;               ///< a file of the suite folder, or "" for oscillating_membrane_quick.toml
  std::vector<std::string> sets;  ///< added to small_membrane_sets(1)
  std::string restart;            ///< a checkpoint of the suite folder, or ""
  std::string message;            ///< expected in the one line on stderr
  std::vector<std::string> args;  ///< further command-line arguments
};

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

/// The octahedron seed of the mesh fuzzing corpus (6-node triangles, Gmsh 2.2) scaled to `radius`, as lines.
std::vector<std::string> octahedron_lines(double radius) {
  std::ifstream in(fs::path(IMMERSE_SOURCE_DIR) / "fuzz" / "corpus" / "mesh" / "octahedron_v22_6node.msh");
  std::vector<std::string> lines;
  bool in_nodes = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "$EndNodes") in_nodes = false;
    if (in_nodes && line.find(' ') != std::string::npos) {
      std::istringstream l(line);
      long tag = 0;
      double x = 0, y = 0, z = 0;
      l >> tag >> x >> y >> z;
      std::ostringstream scaled;
      scaled.precision(17);
      scaled << tag << " " << radius * x << " " << radius * y << " " << radius * z;
      line = scaled.str();
    }
    if (line == "$Nodes") in_nodes = true;
    lines.push_back(line);
  }
  return lines;
}

void write_lines(const fs::path& path, const std::vector<std::string>& lines) {
  std::ofstream f(path);
  for (const auto& l : lines) f << l << "\n";
}

class BadInputTest : public ::testing::TestWithParam<BadInput> {
 public:
  static fs::path suite_dir() { return fs::temp_directory_path() / ("immerse_bad_input_" + std::to_string(getpid())); }

  // A valid checkpoint (one step of the small run), damaged copies of it, and hand-written bad configurations.
  static void SetUpTestSuite() {
    const fs::path dir = suite_dir();
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto good_sets = small_membrane_sets(1);
    good_sets.push_back("output.fields_every=1");  // a frame file, to be offered as a checkpoint
    const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "good", good_sets),
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

    // Damaged entries under a valid checksum (the checkpoint rewritten with one entry replaced).
    auto rewritten = [&](const std::string& name, const std::function<void(io::Checkpoint&)>& put) {
      io::Checkpoint c = io::Checkpoint::read(ck);
      c.erase(name);
      put(c);
      c.write(dir / (name + ".h5"));
    };
    rewritten("step", [](io::Checkpoint& c) { c.put_int("step", -5); });
    rewritten("fluid.u0", [](io::Checkpoint& c) { c.put_array("fluid.u0", std::vector<double>(10, 0.0)); });
    const auto positions = io::Checkpoint::read(ck).array("membrane[0].positions");
    rewritten("membrane[0].positions", [&](io::Checkpoint& c) {
      auto p = positions;
      p[4] = std::nan("");
      c.put_array("membrane[0].positions", p, {p.size() / 3, 3});
    });

    // The quick scenario with its [[membrane]] table repeated: two membranes at the same centre.
    const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
    std::ofstream(dir / "two_membranes.toml") << base << "\n" << base.substr(base.find("[[membrane]]"));
    std::ofstream(dir / "syntax_error.toml") << "[fluid]\nmu = = 1\n";

    // The octahedron of radius 0.2 cut before its fifth element, and with the mid-side node of the first element's
    // first edge (Gmsh node 7) mirrored through the centre, so that the curved elements on that edge fold back.
    auto oct = octahedron_lines(0.2);
    const auto fifth = std::find_if(oct.begin(), oct.end(), [](const std::string& l) { return l.rfind("5 9 ", 0) == 0; });
    write_lines(dir / "truncated.msh", std::vector<std::string>(oct.begin(), fifth));
    auto seven = std::find_if(oct.begin(), oct.end(), [](const std::string& l) { return l.rfind("7 ", 0) == 0; });
    std::istringstream node(*seven);
    double tag = 0, x = 0, y = 0, z = 0;
    node >> tag >> x >> y >> z;
    std::ostringstream mirrored;
    mirrored.precision(17);
    mirrored << "7 " << -x << " " << -y << " " << -z;
    *seven = mirrored.str();
    write_lines(dir / "inverted.msh", oct);

    // A membrane read from a file (cell.msh, found from the configuration's folder) and files that do not fit it:
    // another mesh, the same nodes in other elements, two cells in one file, the cell in millimetres.
    std::ofstream(dir / "file_mesh.toml") << file_membrane_toml("cell.msh");
    const Mesh cell = octahedral_sphere(1);
    write_gmsh(dir / "cell.msh", cell, {0.2, 0.2, 0.2});
    write_gmsh(dir / "coarse.msh", octahedral_sphere(0), {0.2, 0.2, 0.2});
    Mesh reordered = cell;
    std::swap(reordered.elements[0], reordered.elements[1]);
    write_gmsh(dir / "reordered.msh", reordered, {0.2, 0.2, 0.2});
    Mesh two = cell;
    for (const auto& p : cell.nodes) two.nodes.push_back(p + Vec3{2.5, 0, 0});
    for (auto el : cell.elements) {
      for (int& n : el) n += static_cast<int>(cell.num_nodes());
      two.elements.push_back(el);
    }
    write_gmsh(dir / "two_cells.msh", two, {0.2, 0.2, 0.2});
    write_gmsh(dir / "cell_mm.msh", cell, {200, 200, 200});
    // A cigar (semi-axes 1, 0.2, 0.2) bent around the y axis through 8 radians, so that its ends cross (every element
    // sound on its own), and the cell with its file's origin outside it.
    Mesh bent = octahedral_sphere(4);
    for (auto& p : bent.nodes) {
      const double angle = p.x / 0.25, radius = 0.25 + 0.2 * p.z;
      p = {radius * std::sin(angle), 0.2 * p.y, radius * std::cos(angle)};
    }
    write_gmsh(dir / "bent.msh", bent, {0.8, 0.8, 0.8});
    Mesh offset = cell;
    for (auto& p : offset.nodes) p += Vec3{1.5, 0, 0};
    write_gmsh(dir / "offset.msh", offset, {0.2, 0.2, 0.2});

    // An unknown key in the table of another key ([time] mu), and values of 200 kB and 80 kB.
    std::string wrong_table = base;
    wrong_table.replace(wrong_table.find("[time]\n"), 7, "[time]\nmu = 1e-3\n");
    std::ofstream(dir / "wrong_table.toml") << wrong_table;
    std::string long_scheme = base;
    const auto scheme = long_scheme.find("scheme = ");
    long_scheme.replace(scheme, long_scheme.find('\n', scheme) - scheme, "scheme = \"" + std::string(200000, 'x') + "\"");
    std::ofstream(dir / "long_scheme.toml") << long_scheme;
  }
  static void TearDownTestSuite() { fs::remove_all(suite_dir()); }
};

TEST_P(BadInputTest, ExitsWithStatus2AndOneLineBeforeWritingAnything) {
  const BadInput& b = GetParam();
  ScratchDir scratch("bad_input");
  const fs::path out = scratch / "out";
  const fs::path file = b.file.empty() ? scenario_file("oscillating_membrane_quick.toml") : suite_dir() / b.file;
  auto sets = b.file == "file_mesh.toml" ? small_run_sets(1) : small_membrane_sets(1);
  for (std::string set : b.sets) {
    if (const auto at = set.find("SUITE"); at != std::string::npos) set.replace(at, 5, suite_dir().string());
    sets.push_back(set);
  }
  auto args = run_args(file, out, sets, b.restart.empty() ? fs::path{} : suite_dir() / b.restart);
  args.insert(args.end(), b.args.begin(), b.args.end());
  const auto r = run_immerse(args, scratch / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(b.message), std::string::npos) << "expected: " << b.message << "\ngot: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_LT(r.err.size(), 600u) << "a value given is echoed in full";
  EXPECT_FALSE(fs::exists(out)) << "the output folder was created before the input was checked";
}

std::string long_list(std::size_t count) {
  std::string list = "[0.5";
  for (std::size_t i = 1; i < count; ++i) list += ",0.5";
  return list + "]";
}

INSTANTIATE_TEST_SUITE_P(
    Run, BadInputTest,
    ::testing::Values(
        BadInput{"unknown_key", "", {"fluid.muu=1"}, "", "unknown key fluid.muu (did you mean fluid.mu?)"},
        BadInput{"key_in_the_wrong_table", "wrong_table.toml", {}, "", "unknown key time.mu (did you mean fluid.mu?)"},
        BadInput{"long_value_shortened", "long_scheme.toml", {}, "",
                 "time.scheme = \"" + std::string(79, 'x') + "... (200002 characters): must be one of"},
        BadInput{"long_list_shortened", "", {"membrane[0].center=" + long_list(20000)}, "",
                 "membrane[0].center = " + long_list(20000).substr(0, 80) + "... (80001 characters): must be 3 finite"},
        BadInput{"long_mesh_file_name_shortened", "file_mesh.toml",
                 {"membrane[0].mesh.file=\"" + std::string(100000, 'y') + "\""}, "",
                 "cannot open the file: File name too long"},
        BadInput{"self_intersecting_membrane", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE/bent.msh\""}, "",
                 "membrane[0]: its surface intersects itself (elements "},
        BadInput{"reference_sphere_about_an_outside_origin", "file_mesh.toml",
                 {"membrane[0].mesh.file=\"SUITE/offset.msh\"", "membrane[0].reference=\"sphere\""}, "",
                 "membrane[0].reference = \"sphere\": the origin of mesh.file must lie inside the mesh"},
        BadInput{"wrong_type", "", {"fluid.mu=\"thick\""}, "", "fluid.mu = \"thick\": must be a finite number > 0"},
        BadInput{"out_of_range", "", {"fluid.mu=-1"}, "", "fluid.mu = -1: must be a finite number > 0"},
        BadInput{"not_a_number", "", {"fluid.mu=nan"}, "", "fluid.mu = nan: must be a finite number > 0"},
        BadInput{"one_cell", "", {"grid.nx=1"}, "", "grid.nx = 1: must be an integer >= 2"},
        BadInput{"non_cubic_cells", "", {"grid.nz=8"}, "",
                 "grid: cells must be cubic, but Lx/nx = 0.0625 and Lz/nz = 0.125"},
        BadInput{"membrane_outside", "", {"membrane[0].center=[1.5,0.5,0.5]"}, "",
                 "membrane[0] lies outside the box: node 0 at (1.75, 0.5, 0.5) is outside the fluid domain: beyond the "
                 "wall x = 1"},
        BadInput{"viscosity_ratio_out_of_range", "", {"membrane[0].viscosity_ratio=20"}, "",
                 "membrane[0].viscosity_ratio = 20: must be a finite number in [0.1, 10]"},
        BadInput{"viscosity_contrast_at_a_wall", "", {"membrane[0].viscosity_ratio=2", "membrane[0].center=[0.28,0.5,0.5]"},
                 "", "membrane[0] comes within 0.03 m of a wall: must keep at least one cell (0.0625 m) clear"},
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
        BadInput{"missing_mesh_file", "file_mesh.toml", {"membrane[0].mesh.file=\"no_such.msh\""}, "",
                 "membrane[0].mesh no_such.msh: cannot open the file"},
        BadInput{"checkpoint_of_other_grid", "", {"grid.nx=8", "grid.ny=8", "grid.nz=8"}, "good/checkpoint.h5",
                 "checkpoint.h5 was written with grid.nx = 16 (on restart only time.end, time.dt, time.dt_min, "
                 "scenario.kt_end, scenario.k_dt, [output] and [solver] keys may change)"},
        BadInput{"corrupted_checkpoint", "", {}, "flipped.h5", "flipped.h5 is corrupted: checksum mismatch"},
        BadInput{"truncated_checkpoint", "", {}, "truncated.h5", "truncated.h5 is truncated or not an HDF5 file"},
        BadInput{"missing_checkpoint", "", {}, "no_such_checkpoint.h5", "no_such_checkpoint.h5"},
        BadInput{"empty_restart", "", {}, "", "--restart: an empty name was given: must name a checkpoint file",
                 {"--restart", ""}},
        BadInput{"folder_given_to_restart", "", {}, "good", "good is a folder: must name a checkpoint file (e.g. "},
        BadInput{"end_before_checkpoint", "", {}, "good/checkpoint.h5",
                 "time.end = 0.125: must be later than the time of the checkpoint "},
        BadInput{"set_without_key", "", {"="}, "", "--set =: must be KEY=VALUE (no key given; see --help-config)"},
        BadInput{"config_beyond_size_limit", "/dev/zero", {}, "",
                 "config /dev/zero: larger than 1 MiB: not a configuration file"},
        BadInput{"wall_velocity_on_periodic_axis", "", {"boundary.y=\"periodic\"", "boundary.y_upper_velocity=[1,0,0]"},
                 "", "boundary.y_upper_velocity = [1.0, 0.0, 0.0]: must be [0, 0, 0] when boundary.y = \"periodic\" (a "
                     "wall velocity needs walls)"},
        BadInput{"fields_every_beyond_32_bits", "", {"output.fields_every=3000000000"}, "",
                 "output.fields_every = 3000000000: must be a 32-bit integer"},
        BadInput{"checkpoint_negative_step", "", {"time.end=0.5"}, "step.h5",
                 "step.h5: step = -5: must be an integer >= 0"},
        BadInput{"checkpoint_array_too_short", "", {"time.end=0.5"}, "fluid.u0.h5",
                 "fluid.u0.h5: fluid.u0 has 10 values, this configuration needs 4352"},
        BadInput{"checkpoint_nan_position", "", {"time.end=0.5"}, "membrane[0].positions.h5",
                 "membrane[0].positions.h5: membrane[0].positions has a value that is not finite (index 4)"},
        // docs/robustness.md: the hand-tried table.
        BadInput{"boolean_for_a_number", "", {"fluid.mu=true"}, "", "fluid.mu = true: must be a finite number > 0"},
        BadInput{"config_is_a_folder", "good", {}, "", "good: cannot read: Is a directory"},
        BadInput{"infinite_viscosity", "", {"fluid.mu=inf"}, "", "fluid.mu = inf: must be a finite number > 0"},
        BadInput{"zero_density", "", {"fluid.rho=0"}, "", "fluid.rho = 0: must be a finite number > 0"},
        BadInput{"zero_modulus", "", {"membrane[0].Es=0"}, "", "membrane[0].Es = 0: must be a finite number > 0"},
        BadInput{"negative_modulus", "", {"membrane[0].Es=-0.1"}, "",
                 "membrane[0].Es = -0.1: must be a finite number > 0"},
        BadInput{"negative_volume_modulus", "", {"membrane[0].volume_modulus=-1"}, "",
                 "membrane[0].volume_modulus = -1: must be a finite number >= 0"},
        BadInput{"negative_dilation_modulus", "", {"membrane[0].dilation_modulus=-1"}, "",
                 "membrane[0].dilation_modulus = -1: must be a finite number >= 0"},
        BadInput{"unknown_volume_correction", "", {"membrane[0].volume_correction=\"rescale\""}, "",
                 "membrane[0].volume_correction = \"rescale\": must be one of"},
        BadInput{"zero_time_step", "", {"time.dt=0"}, "", "time.dt = 0: must be a finite number > 0"},
        BadInput{"overflowing_time_step", "", {"time.dt=1e400"}, "", "time.dt = 1e400: must be a finite number > 0"},
        BadInput{"step_longer_than_run", "", {"time.dt=2"}, "",
                 "time.dt = 2: must be <= time.end = 0.125 (one step is longer than the run)"},
        BadInput{"step_floor_above_step", "", {"time.dt_min=1"}, "", "time.dt_min = 1: must be in (0, time.dt]"},
        BadInput{"zero_cells", "", {"grid.nx=0"}, "", "grid.nx = 0: must be an integer >= 2"},
        BadInput{"fractional_cells", "", {"grid.nx=16.5"}, "", "grid.nx = 16.5: must be an integer >= 2"},
        BadInput{"cells_beyond_32_bits", "", {"grid.nx=3000000000"}, "", "grid.nx = 3000000000: must be a 32-bit integer"},
        BadInput{"grid_beyond_memory", "", {"grid.nx=100000", "grid.ny=100000", "grid.nz=100000"}, "",
                 "grid 100000 x 100000 x 100000 = 1e+15 cells: needs at least"},
        BadInput{"two_numbers_for_a_point", "", {"membrane[0].center=[0.5,0.5]"}, "",
                 "membrane[0].center = [0.5,0.5]: must be 3 finite numbers [x, y, z]"},
        BadInput{"nan_semi_axis", "", {"membrane[0].semi_axes=[0.25,0.22,nan]"}, "",
                 "membrane[0].semi_axes = [0.25,0.22,nan]: must be 3 finite numbers [x, y, z], each > 0"},
        BadInput{"zero_rotation_axis", "", {"membrane[0].rotation_axis=[0,0,0]", "membrane[0].rotation_angle=1"}, "",
                 "membrane[0].rotation_axis: must be a non-zero vector"},
        BadInput{"flow_rate_between_walls", "", {"fluid.flow_rate=[0.001,0,0]"}, "",
                 "fluid.flow_rate.x: must be zero: a flow rate is held along a periodic axis, and x has walls"},
        BadInput{"flow_rate_along_two_axes", "",
                 {"boundary.x=\"periodic\"", "boundary.y=\"periodic\"", "fluid.flow_rate=[0.001,0.001,0]"}, "",
                 "fluid.flow_rate = [0.001, 0.001, 0.0]: must be zero but along one axis, the axis of the flow"},
        BadInput{"mesh_level_too_fine", "", {"membrane[0].mesh.level=8"}, "",
                 "membrane[0].mesh.level = 8: must be an integer in [0, 7]"},
        BadInput{"membrane_index_gap", "", {"membrane[2].Es=1"}, "", "membrane[2].Es: index 2 given: must be in [0, 1]"},
        BadInput{"missing_mesh_file_key", "file_mesh.toml", {"membrane[0].mesh.file=\"\""}, "",
                 "membrane[0].mesh.file: must be a Gmsh file name when mesh.family = \"file\""},
        BadInput{"shear_without_walls", "", {"scenario.kind=\"capsule_shear\"", "boundary.z=\"periodic\""}, "",
                 "boundary.z: must be \"wall\" for scenario.kind = \"capsule_shear\""},
        BadInput{"derived_group_overflows", "", {"scenario.kind=\"capsule_shear\"", "membrane[0].Es=1e-320"}, "",
                 "scenario.G = inf: must be a finite number > 0 (derived: scenario.kind = \"capsule_shear\" from "
                 "membrane[0].Es"},
        BadInput{"derived_key_conflicts_with_its_group", "", {"scenario.kind=\"capsule_shear\"", "scenario.G=0.1"}, "",
                 "membrane[0].Es = 0.1 conflicts with scenario.G = 0.1 (scenario.kind = \"capsule_shear\" derives "
                 "membrane[0].Es = "},
        BadInput{"wall_velocity_set_by_the_shear_kind", "",
                 {"scenario.kind=\"capsule_shear\"", "boundary.z_upper_velocity=[1,0,0]"}, "",
                 "boundary.z_upper_velocity = [1.0, 0.0, 0.0]: scenario.kind = \"capsule_shear\" sets it to "},
        BadInput{"truncated_mesh", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE/truncated.msh\""}, "",
                 "truncated.msh: truncated or malformed file while reading $Elements"},
        BadInput{"inverted_mesh_element", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE/inverted.msh\""}, "",
                 "inverted.msh: element 0 (gmsh id 1) is inverted"},
        BadInput{"mesh_file_is_a_folder", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE\""}, "",
                 "cannot open the file: it is a directory"},
        // A membrane read from a file: the keys of generated shapes are refused by name, and so are the file keys
        // of a generated membrane.
        BadInput{"file_mesh_radius", "file_mesh.toml", {"membrane[0].radius=0.2"}, "",
                 "membrane[0].radius: does not apply to mesh.family = \"file\" (the file gives the shape; use "
                 "mesh.scale)"},
        BadInput{"file_mesh_shape", "file_mesh.toml", {"membrane[0].shape=\"sphere\""}, "",
                 "membrane[0].shape: does not apply to mesh.family = \"file\""},
        BadInput{"file_mesh_semi_axes", "file_mesh.toml", {"membrane[0].semi_axes=[0.25,0.22,0.2]"}, "",
                 "membrane[0].semi_axes: does not apply to mesh.family = \"file\""},
        BadInput{"file_mesh_aspect_ratio", "file_mesh.toml", {"membrane[0].aspect_ratio=0.5"}, "",
                 "membrane[0].aspect_ratio: does not apply to mesh.family = \"file\""},
        BadInput{"file_mesh_R0", "file_mesh.toml", {"membrane[0].R0=0.2"}, "",
                 "membrane[0].R0: does not apply to mesh.family = \"file\""},
        BadInput{"file_mesh_level", "file_mesh.toml", {"membrane[0].mesh.level=1"}, "",
                 "membrane[0].mesh.level: does not apply to mesh.family = \"file\" (the file gives the nodes)"},
        BadInput{"file_mesh_reference_radius", "file_mesh.toml", {"membrane[0].reference_radius=0.2"}, "",
                 "membrane[0].reference_radius: does not apply unless reference = \"sphere\""},
        BadInput{"reference_file_without_reference_file_kind", "file_mesh.toml",
                 {"membrane[0].mesh.reference_file=\"SUITE/cell.msh\""}, "",
                 "membrane[0].mesh.reference_file: does not apply unless reference = \"file\""},
        BadInput{"generated_mesh_file", "", {"membrane[0].mesh.file=\"SUITE/cell.msh\""}, "",
                 "membrane[0].mesh.file: does not apply unless mesh.family = \"file\""},
        BadInput{"generated_mesh_scale", "", {"membrane[0].mesh.scale=1e-6"}, "",
                 "membrane[0].mesh.scale: does not apply unless mesh.family = \"file\""},
        BadInput{"generated_reference_file", "", {"membrane[0].reference=\"file\""}, "",
                 "membrane[0].reference = \"file\": must be \"initial\" or \"sphere\" unless mesh.family = "
                 "\"file\""},
        BadInput{"reference_file_missing", "file_mesh.toml", {"membrane[0].reference=\"file\""}, "",
                 "membrane[0].mesh.reference_file: must be a Gmsh file name when reference = \"file\""},
        BadInput{"reference_file_other_node_count", "file_mesh.toml",
                 {"membrane[0].reference=\"file\"", "membrane[0].mesh.reference_file=\"SUITE/coarse.msh\""}, "",
                 "membrane[0].mesh.reference_file: has 18 nodes, mesh.file 66 nodes: must be the mesh of mesh.file in "
                 "another shape (the same nodes and elements)"},
        BadInput{"reference_file_other_elements", "file_mesh.toml",
                 {"membrane[0].reference=\"file\"", "membrane[0].mesh.reference_file=\"SUITE/reordered.msh\""}, "",
                 "membrane[0].mesh.reference_file: element 0 joins nodes "},
        BadInput{"two_cells_in_one_file", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE/two_cells.msh\""}, "",
                 "two_cells.msh: holds 2 separate closed surfaces: must be one (give each its own [[membrane]] and "
                 "file)"},
        BadInput{"mesh_in_another_unit", "file_mesh.toml", {"membrane[0].mesh.file=\"SUITE/cell_mm.msh\""}, "",
                 "membrane[0] lies outside the box: node 0 at (200.5, 0.5, 0.5) is outside the fluid domain: beyond "
                 "the wall x = 1 (is the mesh file in another unit? mesh.scale converts it to metres, e.g. 1e-6 for "
                 "micrometres)"},
        BadInput{"frame_offered_as_checkpoint", "", {}, "good/fields_000000.h5",
                 "fields_000000.h5 is not an immerse checkpoint (no format version)"},
        BadInput{"unknown_petsc_option", "", {"solver.petsc_options=\"-ksp_gmres_restartx 10\""}, "",
                 "solver.petsc_options: option -ksp_gmres_restartx was used by none of the 'jfnk' solver's PETSc "
                 "objects (SNES, KSP, PC, MatMFFD) in its first solve"},
        BadInput{"petsc_option_value_rejected", "",
                 {"solver.petsc_options=\"-ksp_type dgmres -ksp_gmres_restart 10 -ksp_dgmres_max_eigen 20\""}, "",
                 "solver.petsc_options = '-ksp_type dgmres -ksp_gmres_restart 10 -ksp_dgmres_max_eigen 20': PETSc "
                 "error in SNESSetFromOptions"},
        BadInput{"unknown_option", "", {}, "", "The following argument was not expected: --sett (see immerse --help)",
                 {"--sett"}}),
    [](const auto& p) { return p.param.name; });

}  // namespace

// A user's mesh file that changed between a run and its restart: the reference state rebuilt from the configuration
// is not the one in the checkpoint, and the restart is refused.
TEST(BadInputRestart, ChangedMeshFileIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("immerse_changed_mesh_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Mesh sphere = octahedral_sphere(1);
  std::ofstream(dir / "cell.toml") << file_membrane_toml("cell.msh");
  write_gmsh(dir / "cell.msh", sphere, {0.2, 0.2, 0.2});
  const auto first = run_immerse(run_args(dir / "cell.toml", dir / "a", small_run_sets(1)), dir / "first");
  ASSERT_EQ(first.status, 0) << first.err;
  write_gmsh(dir / "cell.msh", sphere, {0.21, 0.21, 0.21});
  const auto again =
      run_immerse(run_args(dir / "cell.toml", dir / "a", small_run_sets(2), dir / "a" / "checkpoint.h5"), dir / "again");
  EXPECT_EQ(again.status, 2) << again.err;
  EXPECT_NE(again.err.find("the reference state of membrane[0] differs"), std::string::npos) << again.err;
  fs::remove_all(dir);
}

// A shear scenario whose [[membrane]] table is missing (run as it is: the small-run overrides would add one).
TEST(BadInputMissing, ShearScenarioWithoutItsMembraneTable) {
  ScratchDir scratch("bad_input");
  const std::string shear = read_text(scenario_file("capsule_shear_quick.toml"));
  std::ofstream(scratch / "no_membrane.toml") << shear.substr(0, shear.find("[[membrane]]"));
  const fs::path out = scratch / "out";
  const auto r = run_immerse({"run", (scratch / "no_membrane.toml").string(), "--out", out.string()}, scratch / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "immerse: error: scenario.kind = \"capsule_shear\": needs exactly one [[membrane]]\n");
  EXPECT_FALSE(fs::exists(out));
}

// An empty --out (an unset shell variable) names no folder.
TEST(BadInputOptions, EmptyOutputFolderIsRefused) {
  ScratchDir scratch("bad_input");
  const auto r = run_immerse({"run", scenario_file("oscillating_membrane_quick.toml").string(), "--out", ""},
                             scratch / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "immerse: error: --out: an empty name was given: must name a folder\n");
}

// rbc_stretch with contact patches as wide as the cell: the two patches would pull on the same nodes.
TEST(BadInputScenario, StretchPatchesAsWideAsTheCellAreRefused) {
  ScratchDir scratch("bad_input");
  const fs::path out = scratch / "out";
  const auto r = run_immerse(
      {"run", scenario_file("rbc_stretch_quick.toml").string(), "--out", out.string(), "--set", "scenario.patch_um=8"},
      scratch / "run");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err,
            "immerse: error: scenario.patch_um = 8: the contact patches at the two ends of the cell's diameter along x "
            "(7.82 um) share nodes: must be well below the diameter\n");
  EXPECT_FALSE(fs::exists(out));
}

// A grid that needs more memory than the address-space limit (ulimit -v) leaves, while the program itself fits under
// it: refused before anything is allocated. The limit is set for the child only (inherited through posix_spawn).
// Not in the AddressSanitizer build, whose programs reserve terabytes of address space and cannot start under
// ulimit -v; MemoryLimits.* cover the limits there.
#if !defined(__SANITIZE_ADDRESS__)
TEST(BadInputMemory, GridBeyondTheAddressSpaceLimitIsRefused) {
  ScratchDir scratch("bad_input");
  const fs::path out = scratch / "out";
  auto sets = small_membrane_sets(1);
  sets.insert(sets.end(), {"grid.nx=256", "grid.ny=256", "grid.nz=256"});  // at least 4.19 GB
  rlimit saved{};
  getrlimit(RLIMIT_AS, &saved);
  rlimit limited = saved;
  limited.rlim_cur = rlim_t{2} << 30;
  setrlimit(RLIMIT_AS, &limited);
  ImmerseProcess p(run_args(scenario_file("oscillating_membrane_quick.toml"), out, sets), scratch / "run");
  setrlimit(RLIMIT_AS, &saved);
  EXPECT_EQ(p.wait(), 2) << p.err();
  const std::string err = p.err();
  EXPECT_EQ(err.rfind("immerse: error: grid 256 x 256 x 256 = 1.68e+07 cells: needs at least 4.19 GB, more than the ", 0),
            0u)
      << err;
  EXPECT_NE(err.find(" that the address-space limit (ulimit -v = 2.15 GB) leaves this process\n"), std::string::npos)
      << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(out));
}
#endif

// OMP_NUM_THREADS far above the CPUs: one warning line, and the run goes on.
TEST(RunWarnings, OmpNumThreadsFarAboveTheCpusGivesOneWarningAndRuns) {
  ScratchDir scratch("bad_input");
  const fs::path out = scratch / "out";
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out, small_membrane_sets(1)),
                             scratch / "run", {"OMP_NUM_THREADS=1000"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: warning: OMP_NUM_THREADS = 1000 but ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(fs::exists(out / "checkpoint.h5"));
}
