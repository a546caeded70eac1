// Gmsh reader and closed-mesh validation: hand-written .msh files for each supported form and each defect.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/GmshReader.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/MeshValidation.hpp"

using namespace immerse;

namespace {

// Octahedron |x|+|y|+|z| = 1: Gmsh ids 1..6, faces counter-clockwise from outside (1-based).
const double kOctNodes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const std::vector<std::array<int, 3>> kOctFaces{{1, 3, 5}, {3, 2, 5}, {2, 4, 5}, {4, 1, 5},
                                                {3, 1, 6}, {2, 3, 6}, {4, 2, 6}, {1, 4, 6}};

/// A format-2.2 file of the octahedron's 3-node triangles (Gmsh ids 101..108), preceded by a point and a
/// line element that the reader must ignore. `coords` overrides the node lines when given.
std::string octahedron_v2(std::vector<std::array<int, 3>> faces = kOctFaces, const std::string& coords = "") {
  std::ostringstream s;
  s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"membrane\"\n$EndPhysicalNames\n";
  s << "$Nodes\n6\n";
  if (coords.empty())
    for (int i = 0; i < 6; ++i) s << i + 1 << " " << kOctNodes[i][0] << " " << kOctNodes[i][1] << " " << kOctNodes[i][2] << "\n";
  else
    s << coords;
  s << "$EndNodes\n$Elements\n" << faces.size() + 2 << "\n1 15 2 0 1 1\n2 1 2 0 1 1 3\n";
  for (std::size_t e = 0; e < faces.size(); ++e)
    s << 101 + e << " 2 2 1 1 " << faces[e][0] << " " << faces[e][1] << " " << faces[e][2] << "\n";
  s << "$EndElements\n";
  return s.str();
}

/// A format-2.2 file of a quadratic mesh (type 9), node ids 1-based.
std::string quadratic_v2(const Mesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << m.num_nodes() << "\n";
  for (std::size_t i = 0; i < m.num_nodes(); ++i)
    s << i + 1 << " " << m.nodes[i].x << " " << m.nodes[i].y << " " << m.nodes[i].z << "\n";
  s << "$EndNodes\n$Elements\n" << m.num_elements() << "\n";
  for (std::size_t e = 0; e < m.num_elements(); ++e) {
    s << e + 1 << " 9 2 0 1";
    for (int v : m.elements[e]) s << " " << v + 1;
    s << "\n";
  }
  s << "$EndElements\n";
  return s.str();
}

/// A temporary file name of this process (ctest runs tests of this program in parallel processes).
std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("immerse_test_" + std::to_string(getpid()) + "_" + name);
}

/// Writes `text` to a temporary .msh file and reads it back.
Mesh read_text(const std::string& text, const std::string& name = "cell.msh") {
  const auto path = temp_path(name);
  std::ofstream(path) << text;
  Mesh m = read_gmsh(path.string());
  std::filesystem::remove(path);
  return m;
}

/// The InputError message of reading `text`, or "" if it was accepted.
std::string error_of(const std::string& text) {
  try {
    read_text(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

::testing::AssertionResult contains(const std::string& msg, const std::string& part) {
  if (msg.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << msg << "' does not contain '" << part << "'";
}

}  // namespace

TEST(GmshReader, PromotesLinearTrianglesAndIgnoresPointsAndLines) {
  const Mesh m = read_text(octahedron_v2());
  EXPECT_EQ(m.num_elements(), 8u);
  EXPECT_EQ(m.num_nodes(), 6u + 12u);  // 12 edges, one shared mid-side node each
  // Straight-edge midpoints keep the flat octahedron: V = 4/3, S = 8 (√3/4)(√2)² = 4√3.
  EXPECT_NEAR(volume(m, m.nodes), 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(area(m, m.nodes), 4 * std::sqrt(3.0), 1e-13);
}

TEST(GmshReader, FlipsAConsistentlyInwardSurface) {
  auto faces = kOctFaces;
  for (auto& f : faces) std::swap(f[1], f[2]);
  const Mesh m = read_text(octahedron_v2(faces));
  EXPECT_NEAR(volume(m, m.nodes), 4.0 / 3.0, 1e-14);
  for (const auto& e : m.elements)
    EXPECT_GT(dot(cross(m.nodes[e[1]] - m.nodes[e[0]], m.nodes[e[2]] - m.nodes[e[0]]), m.nodes[e[0]]), 0.0);
}

TEST(GmshReader, ReadsQuadraticTrianglesExactly) {
  const Mesh sphere = icosahedral_sphere(2);
  const Mesh m = read_text(quadratic_v2(sphere));
  ASSERT_EQ(m.num_nodes(), sphere.num_nodes());
  ASSERT_EQ(m.num_elements(), sphere.num_elements());
  EXPECT_EQ(m.elements, sphere.elements);  // all nodes used: the file's numbering is kept
  for (std::size_t i = 0; i < m.num_nodes(); ++i) EXPECT_EQ(norm(m.nodes[i] - sphere.nodes[i]), 0.0);
  EXPECT_DOUBLE_EQ(volume(m, m.nodes), volume(sphere, sphere.nodes));
}

TEST(GmshReader, ReadsFormat41) {
  std::ostringstream s;
  s << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 -1 -1 -1 1 1 1 0 0\n$EndEntities\n";
  // Second node block on a surface entity with parametric coordinates (u, v) after x y z.
  s << "$Nodes\n2 6 1 6\n0 1 0 1\n1\n1 0 0\n2 1 1 5\n2\n3\n4\n5\n6\n";
  for (int i = 1; i < 6; ++i)
    s << kOctNodes[i][0] << " " << kOctNodes[i][1] << " " << kOctNodes[i][2] << " 0.25 0.5\n";
  s << "$EndNodes\n$Elements\n2 9 1 9\n0 1 15 1\n1 1\n2 1 2 8\n";
  for (std::size_t e = 0; e < kOctFaces.size(); ++e)
    s << 2 + e << " " << kOctFaces[e][0] << " " << kOctFaces[e][1] << " " << kOctFaces[e][2] << "\n";
  s << "$EndElements\n";
  const Mesh m = read_text(s.str());
  EXPECT_EQ(m.num_elements(), 8u);
  EXPECT_NEAR(volume(m, m.nodes), 4.0 / 3.0, 1e-14);
}

// Some editors start a text file with a UTF-8 byte-order mark; it is not part of "$MeshFormat".
TEST(GmshReader, AcceptsAByteOrderMark) {
  const Mesh m = read_text("\xEF\xBB\xBF" + octahedron_v2());
  EXPECT_EQ(m.num_elements(), 8u);
  EXPECT_NEAR(volume(m, m.nodes), 4.0 / 3.0, 1e-14);
}

// Two closed surfaces in one file (two octahedra, each closed and outward): refused naming the count.
TEST(GmshReader, RejectsMoreThanOneClosedSurface) {
  std::ostringstream coords;
  for (int copy = 0; copy < 2; ++copy)
    for (int i = 0; i < 6; ++i)
      coords << 6 * copy + i + 1 << " " << kOctNodes[i][0] + 3 * copy << " " << kOctNodes[i][1] << " "
             << kOctNodes[i][2] << "\n";
  auto faces = kOctFaces;
  for (const auto& f : kOctFaces) faces.push_back({f[0] + 6, f[1] + 6, f[2] + 6});
  std::string text = octahedron_v2(faces, coords.str());
  text.replace(text.find("$Nodes\n6\n"), 9, "$Nodes\n12\n");
  EXPECT_EQ(error_of(text), "mesh " + temp_path("cell.msh").string() +
                                ": holds 2 separate closed surfaces: must be one (give each its own [[membrane]] and file)");
}

TEST(GmshReader, RejectsAnOpenSurface) {
  auto faces = kOctFaces;
  faces.pop_back();
  const std::string msg = error_of(octahedron_v2(faces));
  EXPECT_TRUE(contains(msg, "cell.msh"));
  EXPECT_TRUE(contains(msg, "gmsh id"));
  EXPECT_TRUE(contains(msg, "the surface is open"));
}

TEST(GmshReader, RejectsANonManifoldEdge) {
  auto faces = kOctFaces;  // a second octahedron sharing only the edge 1-3 with the first
  faces.push_back({1, 3, 7});
  faces.push_back({3, 1, 8});
  const std::string coords =
      "1 1 0 0\n2 -1 0 0\n3 0 1 0\n4 0 -1 0\n5 0 0 1\n6 0 0 -1\n7 2 2 0.5\n8 2 2 -0.5\n";
  std::string text = octahedron_v2(faces, coords);
  text.replace(text.find("$Nodes\n6\n"), 9, "$Nodes\n8\n");
  EXPECT_TRUE(contains(error_of(text), "non-manifold"));
}

TEST(GmshReader, RejectsInconsistentOrientation) {
  auto faces = kOctFaces;
  std::swap(faces[3][1], faces[3][2]);
  const std::string msg = error_of(octahedron_v2(faces));
  EXPECT_TRUE(contains(msg, "oriented inconsistently"));
  EXPECT_TRUE(contains(msg, "(gmsh id 10"));
}

TEST(GmshReader, RejectsAZeroAreaElement) {
  // Node 5 moved onto the segment between nodes 1 and 3: face (1, 3, 5) collapses.
  const std::string coords = "1 1 0 0\n2 -1 0 0\n3 0 1 0\n4 0 -1 0\n5 0.5 0.5 0\n6 0 0 -1\n";
  EXPECT_EQ(error_of(octahedron_v2(kOctFaces, coords)), "mesh " +
            temp_path("cell.msh").string() +
            ": element 0 (gmsh id 101) has zero area");
}

TEST(GmshReader, RejectsAnElementWithARepeatedNode) {
  auto faces = kOctFaces;
  faces[2] = {2, 4, 4};
  EXPECT_TRUE(contains(error_of(octahedron_v2(faces)), "element 2 (gmsh id 103) is degenerate"));
}

TEST(GmshReader, RejectsAnInvertedCurvedElement) {
  Mesh sphere = octahedral_sphere(1);
  const auto& e = sphere.elements[5];
  // Mid-side node at 95% of its edge: the quadratic map folds back near the vertex v1.
  sphere.nodes[e[3]] = 0.05 * sphere.nodes[e[0]] + 0.95 * sphere.nodes[e[1]];
  EXPECT_TRUE(contains(error_of(quadratic_v2(sphere)), "is inverted"));
}

TEST(GmshReader, RejectsNonFiniteCoordinates) {
  const std::string coords = "1 1 0 0\n2 -1 0 0\n3 0 nan 0\n4 0 -1 0\n5 0 0 1\n6 0 0 inf\n";
  const std::string msg = error_of(octahedron_v2(kOctFaces, coords));
  EXPECT_TRUE(contains(msg, "(gmsh id 3) has non-finite coordinates"));
}

TEST(GmshReader, RejectsUnknownNodeIds) {
  auto faces = kOctFaces;
  faces[4][2] = 99;
  EXPECT_TRUE(contains(error_of(octahedron_v2(faces)), "element 4 (gmsh id 105) references unknown node id 99"));
}

TEST(GmshReader, RejectsTruncatedAndMalformedFiles) {
  const std::string full = octahedron_v2();
  EXPECT_TRUE(contains(error_of(full.substr(0, full.find("105 2"))), "truncated"));
  EXPECT_TRUE(contains(error_of(full.substr(0, full.find("$EndElements"))), "truncated"));
  EXPECT_TRUE(contains(error_of(full.substr(0, full.find("4 0 -1 0"))), "truncated"));
  EXPECT_TRUE(contains(error_of("hello\n"), "no $MeshFormat"));
  std::string binary = full;
  binary.replace(binary.find("2.2 0 8"), 7, "2.2 1 8");
  EXPECT_TRUE(contains(error_of(binary), "binary"));
  std::string bad_number = full;
  bad_number.replace(bad_number.find("4 0 -1 0"), 8, "4 0 -1x 0");
  EXPECT_TRUE(contains(error_of(bad_number), "malformed coordinate '-1x'"));
  EXPECT_TRUE(contains(error_of(octahedron_v2({})), "no triangles"));
  EXPECT_THROW(read_gmsh("/nonexistent/cell.msh"), InputError);
}

TEST(MeshValidation, NamesNodesAndElementsOfGeneratedMeshes) {
  Mesh m = icosahedral_sphere(1);
  validate_closed_mesh(m, "sphere");
  m.nodes.push_back({2, 0, 0});
  try {
    validate_closed_mesh(m, "sphere");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "mesh sphere: node 162 is not used by any element");
  }
  m.nodes.pop_back();
  m.elements[7][4] = 5000;
  EXPECT_TRUE(contains([&] {
    try { validate_closed_mesh(m, "sphere"); } catch (const InputError& e) { return std::string(e.what()); }
    return std::string();
  }(), "element 7 references unknown node 5000"));
}

TEST(MeshValidation, RejectsInwardOrientationAndNonConformingMidsideNodes) {
  Mesh m = octahedral_sphere(1);
  for (auto& el : m.elements) el = {el[0], el[2], el[1], el[5], el[4], el[3]};
  EXPECT_THROW(validate_closed_mesh(m, "inward"), InputError);
  orient_outward(m);
  validate_closed_mesh(m, "outward again");

  Mesh nc = octahedral_sphere(1);
  nc.nodes.push_back(nc.nodes[nc.elements[0][3]]);  // a duplicate of a shared mid-side node
  nc.elements[0][3] = static_cast<int>(nc.nodes.size() - 1);
  try {
    validate_closed_mesh(nc, "nc");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), "different mid-side nodes"));
  }
}
