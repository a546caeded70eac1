#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/CellFields.hpp"
#include "immerse/io/CsvWriter.hpp"
#include "immerse/io/Hdf5.hpp"
#include "immerse/io/OutputFolder.hpp"
#include "immerse/io/XdmfWriter.hpp"

using namespace immerse;
using namespace immerse::io;
namespace fs = std::filesystem;

namespace {

// Removes this program's temporary directory at the end.
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    fs::remove_all(fs::temp_directory_path() / ("immerse_test_output_" + std::to_string(::getpid())));
  }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("immerse_test_output_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool no_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) return false;
  return true;
}

// Face velocity u_d(x) sampled at the MAC positions of `g`.
template <class F>
FaceField sample_faces(const Grid& g, F&& velocity) {
  FaceField u(g);
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k < u[d].nz(); ++k)
      for (int j = 0; j < u[d].ny(); ++j)
        for (int i = 0; i < u[d].nx(); ++i) u[d](i, j, k) = velocity(g.face_position(d, i, j, k))[d];
  return u;
}

const std::array<Boundary, 3> kPeriodic{Boundary::Periodic, Boundary::Periodic, Boundary::Periodic};
const std::array<Boundary, 3> kWallY{Boundary::Periodic, Boundary::Wall, Boundary::Periodic};

}  // namespace

// ------------------------------------------------------------------------------------------------ AtomicFile

TEST(AtomicFile, ReplacesWholeFileAndLeavesNoTemporary) {
  const fs::path dir = scratch("atomic");
  AtomicFile::write(dir / "a.txt", "first version\n");
  AtomicFile::write(dir / "a.txt", "second\n");
  EXPECT_EQ(slurp(dir / "a.txt"), "second\n");
  EXPECT_TRUE(no_temporaries(dir));
  AtomicFile f(dir / "b.txt");
  EXPECT_EQ(f.temp_path(), dir / ("b.txt.tmp." + std::to_string(::getpid())));
}

TEST(AtomicFile, FailureNamesPathAndErrnoAndLeavesNothing) {
  const fs::path dir = scratch("atomic_fail");
  std::ofstream(dir / "plain") << "x";
  // Tests run as root, so permissions do not block writing: use a parent that is a regular file, and /proc.
  EXPECT_EQ(error_of([&] { AtomicFile::write(dir / "plain" / "diag.csv", "x"); }),
            "cannot write " + (dir / "plain" / "diag.csv").string() + ": Not a directory");
  EXPECT_EQ(error_of([] { AtomicFile::write("/proc/immerse_diag.csv", "x"); }),
            "cannot write /proc/immerse_diag.csv: No such file or directory");
  EXPECT_EQ(error_of([&] { AtomicFile::write(dir / "missing" / "x.csv", "x"); }),
            "cannot write " + (dir / "missing" / "x.csv").string() + ": No such file or directory");
  EXPECT_TRUE(no_temporaries(dir));
}

// ------------------------------------------------------------------------------------------------ CsvWriter

TEST(CsvWriter, FullPrecisionRowsAndAppendOnRestart) {
  const fs::path p = scratch("csv") / "diag.csv";
  const double third = 1.0 / 3.0, tiny = 1e-310;
  {
    CsvWriter w(p, {"time", "energy", "volume"});
    w.row({0.0, third, tiny});
    EXPECT_EQ(slurp(p), "time,energy,volume\n0,0.33333333333333331,9.9999999999999694e-311\n");  // flushed per row
    w.row({0.1, -2.0, 1e300});
  }
  {
    CsvWriter w(p, {"time", "energy", "volume"}, CsvWriter::Mode::Append);
    w.row({0.2, 3.0, 4.0});
  }
  std::ifstream in(p);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "time,energy,volume");
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) r.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(r);
  }
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0][1], third);  // bitwise round trip through %.17g
  EXPECT_EQ(rows[0][2], tiny);
  EXPECT_EQ(rows[1][2], 1e300);
  EXPECT_EQ(rows[2][0], 0.2);

  // Create replaces the old file.
  { CsvWriter w(p, {"time", "energy", "volume"}); }
  EXPECT_EQ(slurp(p), "time,energy,volume\n");
}

TEST(CsvWriter, AppendRefusesAnotherHeaderAndBadRowsAreCaught) {
  const fs::path p = scratch("csv_bad") / "diag.csv";
  { CsvWriter w(p, {"time", "energy"}); }
  EXPECT_EQ(error_of([&] { CsvWriter(p, {"time", "volume"}, CsvWriter::Mode::Append); }),
            "cannot continue " + p.string() + ": header is \"time,energy\", this run writes \"time,volume\"");
  CsvWriter w(p, {"time", "energy"}, CsvWriter::Mode::Append);
  EXPECT_THROW(w.row({1.0}), std::logic_error);
  EXPECT_EQ(error_of([&] { CsvWriter(p.parent_path() / "diag.csv" / "x.csv", {"t"}); }),
            "cannot write " + (p / "x.csv").string() + ": Not a directory");
}

// ------------------------------------------------------------------------------------------------ CellFields

TEST(CellFields, VorticityIsSecondOrderOnPeriodicGrid) {
  // u = (sin 2pi y, sin 2pi z, sin 2pi x): curl u = -2pi (cos 2pi z, cos 2pi x, cos 2pi y).
  const double tp = 2 * std::numbers::pi;
  const auto vel = [&](const Vec3& x) { return Vec3{std::sin(tp * x.y), std::sin(tp * x.z), std::sin(tp * x.x)}; };
  std::vector<double> err;
  for (const int n : {8, 16, 32}) {
    const Grid g({n, n, n}, {1, 1, 1}, kPeriodic);
    const CellFields c = CellFields::from_faces(g, sample_faces(g, vel));
    double e = 0, eu = 0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 x = g.cell_position(i, j, k);
          const double exact =
              tp * std::sqrt(std::pow(std::cos(tp * x.z), 2) + std::pow(std::cos(tp * x.x), 2) +
                             std::pow(std::cos(tp * x.y), 2));
          e = std::max(e, std::abs(c.vorticity_magnitude(i, j, k) - exact));
          eu = std::max(eu, std::abs(c.velocity[0](i, j, k) - vel(x).x));
        }
    EXPECT_LT(eu, 1e-14);  // u_x does not vary along x: the face average is exact
    err.push_back(e);
  }
  const double p1 = std::log2(err[0] / err[1]), p2 = std::log2(err[1] / err[2]);
  std::cout << "max |omega| error n=8,16,32: " << err[0] << " " << err[1] << " " << err[2] << "  orders " << p1
            << " " << p2 << "\n";
  EXPECT_GT(p2, 1.9);
  EXPECT_LT(p2, 2.1);
}

TEST(CellFields, WallBoundedPolynomialFlowsAreExact) {
  // Couette-Poiseuille between walls y = 0, 1: u_x = a y + b y (1 - y), omega_z = -(a + b (1 - 2y)).
  const double a = 0.7, b = 2.0;
  const Grid g({4, 6, 3}, {2.0 / 3.0, 1, 0.5}, kWallY, {0.1, 0.0, -0.3});
  const auto vel = [&](const Vec3& x) { return Vec3{a * x.y + b * x.y * (1 - x.y), 0, 0}; };
  const CellFields c = CellFields::from_faces(g, sample_faces(g, vel));
  double e = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 4; ++i) {
        const double y = g.cell_position(i, j, k).y;
        e = std::max(e, std::abs(c.vorticity_magnitude(i, j, k) - std::abs(a + b * (1 - 2 * y))));
        e = std::max(e, std::abs(c.velocity[0](i, j, k) - vel(g.cell_position(i, j, k)).x));
      }
  EXPECT_LT(e, 1e-13);
  // A linear velocity along a wall axis is averaged exactly between the two bounding faces.
  const auto vy = [](const Vec3& x) { return Vec3{0, 3 * x.y - 1, 0}; };
  const CellFields d = CellFields::from_faces(g, sample_faces(g, vy));
  EXPECT_NEAR(d.velocity[1](1, 0, 1), 3 * g.cell_center(1, 0) - 1, 1e-15);
  EXPECT_NEAR(d.velocity[1](1, 5, 1), 3 * g.cell_center(1, 5) - 1, 1e-15);
}

// ------------------------------------------------------------------------------------------------ XdmfWriter

namespace {

struct HdfRef {
  std::string dims, file, dataset;
};

// The text between `open` and the next `close`, for every occurrence of `open`.
std::vector<std::string> between(const std::string& xml, const std::string& open, const std::string& close) {
  std::vector<std::string> out;
  for (auto a = xml.find(open); a != std::string::npos; a = xml.find(open, a + 1)) {
    const auto b = a + open.size();
    out.push_back(xml.substr(b, xml.find(close, b) - b));
  }
  return out;
}

// Every <DataItem Dimensions="..." ... Format="HDF">file:/dataset</DataItem> of an XDMF text.
std::vector<HdfRef> hdf_refs(const std::string& xml) {
  std::vector<HdfRef> out;
  for (const auto& item : between(xml, "<DataItem Dimensions=\"", "</DataItem>")) {
    const auto fmt = item.find("Format=\"HDF\">");
    if (fmt == std::string::npos) continue;
    const std::string ref = item.substr(fmt + 13);
    const auto colon = ref.find(':');
    out.push_back({item.substr(0, item.find('"')), ref.substr(0, colon), ref.substr(colon + 1)});
  }
  return out;
}

std::vector<std::string> times(const std::string& xml) { return between(xml, "<Time Value=\"", "\"/>"); }

std::string dims_of(const fs::path& file, const std::string& dataset) {
  hdf5::Handle f = hdf5::open_file_readonly(file);
  std::vector<hsize_t> dims;
  if (!f.valid() || !hdf5::dataset_dims(f.get(), dataset, dims)) return "missing";
  std::string s;
  for (const auto d : dims) s.append(s.empty() ? "" : " ").append(std::to_string(d));
  return s;
}

// One quadratic triangle and a two-triangle patch, with frame-dependent values.
struct Surface {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 6>> tris;
  std::vector<Vec3> force;
  std::vector<double> tension;
};

Surface surface(int nt, double shift) {
  Surface s;
  const int nn = nt == 1 ? 6 : 9;
  for (int i = 0; i < nn; ++i) {
    s.nodes.push_back({i + shift, 0.5 * i, -0.25 * i});
    s.force.push_back({std::sin(i + shift), std::cos(i * shift), 1.0 / (i + 1)});
    s.tension.push_back(i * i + shift);
  }
  s.tris.push_back({0, 1, 2, 3, 4, 5});
  if (nt == 2) s.tris.push_back({1, 6, 2, 7, 8, 4});
  return s;
}

}  // namespace

TEST(XdmfWriter, TwoFramesReadBackExactlyAndXdmfReferencesThem) {
  const fs::path dir = scratch("xdmf");
  const Grid g({4, 3, 5}, {1, 0.75, 1.25}, kWallY, {-0.5, 0, 1});
  XdmfWriter w(dir);
  std::vector<std::vector<double>> written_pressure;
  for (int frame = 0; frame < 2; ++frame) {
    const double shift = 0.125 * frame;
    const Surface a = surface(1, shift), b = surface(2, shift);
    const SurfaceFrame sa{"capsule0", a.nodes, a.tris, {{"force", a.force}}, {{"tension", a.tension}}};
    const SurfaceFrame sb{"cell1", b.nodes, b.tris, {{"force", b.force}}, {{"tension", b.tension}}};
    const std::vector<SurfaceFrame> surfaces{sa, sb};
    const FaceField u = sample_faces(g, [&](const Vec3& x) { return Vec3{x.y * (0.75 - x.y) + shift, x.z, x.x}; });
    Array3 p(4, 3, 5);
    for (std::size_t c = 0; c < p.size(); ++c) p[c] = std::sin(0.1 * static_cast<double>(c)) + shift;
    written_pressure.push_back(p.values());
    const FluidFrame fluid{g, u, p};
    const fs::path h5 = w.write_frame(0.5 * frame + 0.1, surfaces, &fluid);
    EXPECT_EQ(h5, dir / XdmfWriter::frame_file_name(frame));

    // Read back with the HDF5 API: bitwise equal to what was given, the second membrane's nodes after the first's.
    hdf5::Handle f = hdf5::open_file_readonly(h5);
    ASSERT_TRUE(f.valid());
    std::vector<double> v;
    std::vector<std::int32_t> conn;
    std::vector<hsize_t> dims;
    const std::size_t na = a.nodes.size();
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/membranes/nodes", v, dims));
    EXPECT_EQ(dims, (std::vector<hsize_t>{na + 9, 3}));
    for (std::size_t i = 0; i < b.nodes.size(); ++i)
      for (int d = 0; d < 3; ++d) EXPECT_EQ(v[3 * (na + i) + d], b.nodes[i][d]);
    ASSERT_TRUE(hdf5::read_int32(f.get(), "/membranes/connectivity", conn, dims));
    EXPECT_EQ(dims, (std::vector<hsize_t>{a.tris.size() + 2, 6}));
    const std::vector<std::int32_t> second(conn.end() - 12, conn.end());
    std::vector<std::int32_t> expected{0, 1, 2, 3, 4, 5, 1, 6, 2, 7, 8, 4};
    for (auto& e : expected) e += static_cast<std::int32_t>(na);
    EXPECT_EQ(second, expected);
    ASSERT_TRUE(hdf5::read_int32(f.get(), "/membranes/membrane_id", conn, dims));
    std::vector<std::int32_t> ids(a.tris.size(), 0);
    ids.insert(ids.end(), 2, 1);
    EXPECT_EQ(conn, ids);
    std::string names;
    hdf5::Handle group = hdf5::open_group(f.get(), "membranes");
    ASSERT_TRUE(group.valid() && hdf5::read_attribute(group.get(), "names", names));
    EXPECT_EQ(names, "capsule0 cell1");
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/membranes/tension", v, dims));
    EXPECT_EQ(std::vector<double>(v.begin(), v.begin() + static_cast<long>(na)), a.tension);
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/membranes/force", v, dims));
    for (std::size_t i = 0; i < a.force.size(); ++i)
      for (int d = 0; d < 3; ++d) EXPECT_EQ(v[3 * i + d], a.force[i][d]);
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/fluid/pressure", v, dims));
    EXPECT_EQ(dims, (std::vector<hsize_t>{5, 3, 4}));
    EXPECT_EQ(v, written_pressure.back());
    const CellFields cells = CellFields::from_faces(g, u);
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/fluid/velocity", v, dims));
    EXPECT_EQ(dims, (std::vector<hsize_t>{5, 3, 4, 3}));
    for (std::size_t c = 0; c < cells.velocity[0].size(); ++c)
      for (int d = 0; d < 3; ++d) EXPECT_EQ(v[3 * c + d], cells.velocity[d][c]);
    ASSERT_TRUE(hdf5::read_doubles(f.get(), "/fluid/vorticity_magnitude", v, dims));
    EXPECT_EQ(v, cells.vorticity_magnitude.values());
    double t = 0;
    ASSERT_TRUE(hdf5::read_attribute(f.get(), "time", t));
    EXPECT_EQ(t, 0.5 * frame + 0.1);
  }
  EXPECT_TRUE(no_temporaries(dir));

  const std::string mx = slurp(dir / "membranes.xdmf"), fx = slurp(dir / "fluid.xdmf");
  EXPECT_NE(mx.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(times(mx), (std::vector<std::string>{"0.1", "0.6"}));
  EXPECT_EQ(times(fx), (std::vector<std::string>{"0.1", "0.6"}));
  EXPECT_NE(mx.find("<Topology TopologyType=\"Triangle_6\" NumberOfElements=\""), std::string::npos);
  EXPECT_NE(mx.find("<Information Name=\"membrane_names\" Value=\"capsule0 cell1\"/>"), std::string::npos);
  EXPECT_NE(mx.find("<Attribute Name=\"membrane_id\" AttributeType=\"Scalar\" Center=\"Cell\">"), std::string::npos);
  EXPECT_NE(fx.find("<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"5 3 4\"/>"), std::string::npos);
  // Origin of the cell centres in z, y, x order, then the spacing.
  EXPECT_NE(fx.find("Format=\"XML\">1.125 0.125 -0.375</DataItem>"), std::string::npos) << fx;
  EXPECT_NE(fx.find("Format=\"XML\">0.25 0.25 0.25</DataItem>"), std::string::npos);
  // Every referenced dataset exists with the stated dimensions.
  const auto mrefs = hdf_refs(mx), frefs = hdf_refs(fx);
  // Per frame, one grid of both membranes: connectivity, nodes, membrane_id, position (the nodes) and two fields.
  EXPECT_EQ(mrefs.size(), 2u * 6);
  EXPECT_EQ(frefs.size(), 2u * 3);
  for (const auto* refs : {&mrefs, &frefs})
    for (const auto& r : *refs) EXPECT_EQ(dims_of(dir / r.file, r.dataset), r.dims) << r.file << ":" << r.dataset;
}

TEST(XdmfWriter, RestartContinuesTheSeries) {
  const fs::path dir = scratch("xdmf_restart");
  const Surface a = surface(1, 0);
  const std::vector<SurfaceFrame> s{{"m", a.nodes, a.tris, {}, {{"tension", a.tension}}}};
  {
    XdmfWriter w(dir);
    for (int f = 0; f < 3; ++f) w.write_frame(f, s);
  }
  const std::string before = slurp(dir / "membranes.xdmf");
  XdmfWriter w(dir, 2);  // the run restarts from the checkpoint taken after frame 1
  EXPECT_EQ(w.frames(), 2);
  w.write_frame(1.5, s);
  const std::string after = slurp(dir / "membranes.xdmf");
  EXPECT_EQ(times(after), (std::vector<std::string>{"0", "1", "1.5"}));
  EXPECT_EQ(times(slurp(dir / "fluid.xdmf")).size(), 0u);  // no fluid given
  EXPECT_EQ(after.substr(0, before.find("membranes_000002")), before.substr(0, before.find("membranes_000002")));

  EXPECT_EQ(error_of([&] { XdmfWriter(dir, 5); }), "cannot continue the output series: " +
                                                       (dir / "fields_000003.h5").string() +
                                                       " is missing, truncated or not written by immerse");
  std::ofstream(dir.parent_path() / "xdmf_plain") << "x";
  EXPECT_EQ(error_of([&] { XdmfWriter(dir.parent_path() / "xdmf_plain" / "out"); }).rfind("cannot write ", 0), 0u);
}

// The copies of mesh files count as a run's files (listed, removed by --overwrite); a user's own mesh file in the
// folder does not.
TEST(OutputFolderFiles, MeshCopiesAreRunFiles) {
  for (const char* name : {"mesh_membrane0.msh", "mesh_membrane12_reference.msh", "mesh_membrane3.msh.tmp.77"})
    EXPECT_TRUE(OutputFolder::is_run_file(name) || OutputFolder::is_temporary(name)) << name;
  for (const char* name : {"cell.msh", "mesh_membrane.msh", "mesh_membrane0_rest.msh", "mesh_membranex.msh"})
    EXPECT_FALSE(OutputFolder::is_run_file(name)) << name;
  const fs::path dir = scratch("mesh_copies");
  for (const char* name : {"mesh_membrane0.msh", "mesh_membrane0_reference.msh", "cell.msh"})
    std::ofstream(dir / name) << "x";
  OutputFolder folder(dir);
  EXPECT_EQ(folder.run_files(), (std::vector<std::string>{"mesh_membrane0.msh", "mesh_membrane0_reference.msh"}));
  folder.remove_run_files();
  EXPECT_TRUE(folder.run_files().empty());
  EXPECT_TRUE(fs::exists(dir / "cell.msh"));
}
