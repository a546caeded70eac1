// CellPacking: copies of one membrane at random positions and orientations with no two closer than the clearance,
// reproducible by seed; through the program, [packing] fills the box to the volume fraction asked for.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>

#include "immerse/contact/CellPacking.hpp"
#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/Shape.hpp"
#include "immerse/walls/WallGeometry.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

// Unit spheres of 162 nodes (vertex to mid-side node at most 0.2) in a box of side 8, h = 0.25; clearance 0.3.
struct SphereBox {
  Grid grid;
  Mesh mesh = icosahedral_sphere(1);
  double spacing = 0.21;
  explicit SphereBox(Boundary z) : grid({32, 32, 32}, {8, 8, 8}, {Boundary::Periodic, Boundary::Periodic, z}) {}
  std::vector<std::vector<Vec3>> place(const PackingRequest& r) const {
    const CellPacking p(grid, mesh.nodes, spacing, r, "packing.count");
    std::vector<std::vector<Vec3>> X;
    for (const auto& t : p.placements()) {
      X.emplace_back();
      for (const auto& q : mesh.nodes) X.back().push_back(t.rotation * q + t.translation);
    }
    return X;
  }
};

}  // namespace

// 12 spheres in a tube of radius 2.6 along z ([[wall]]): every node at least the clearance inside the tube, no two
// copies closer than it; the start size and the volume fraction are the tube's.
TEST(CellPacking, SpheresInATube) {
  const SphereBox s(Boundary::Periodic);
  PackingRequest r;
  r.count = 12;
  r.seed = 5;
  r.clearance = 0.3;
  r.walls = std::make_shared<const WallGeometry>(
      std::vector<WallShape>{{WallShape::Kind::Tube, {4, 4, 4}, {0, 0, 1}, 2.6, 0, "wall[0]"}}, s.grid);
  const auto X = s.place(r);
  ASSERT_EQ(X.size(), 12u);  // 12 unit spheres: 30 % of the tube's 170
  EXPECT_FALSE(closest_foreign_nodes(s.grid, X, r.clearance).has_value());
  double nearest = 1e9;
  for (const auto& cell : X)
    for (const auto& p : cell) nearest = std::min(nearest, r.walls->distance(p));
  EXPECT_GE(nearest, r.clearance);
  EXPECT_NEAR(r.walls->fluid_volume(s.grid), M_PI * 2.6 * 2.6 * 8, 0.01 * M_PI * 2.6 * 2.6 * 8);
}

// 30 spheres (volume fraction 0.25) between walls z = 0 and z = 8: every pair of nodes of two spheres at least the
// clearance apart (minimum images across the periodic sides), every node at least the clearance from the walls,
// and no sphere inside another.
TEST(CellPacking, NoTwoCopiesCloserThanTheClearance) {
  const SphereBox s(Boundary::Wall);
  PackingRequest r;
  r.count = 30;
  r.seed = 7;
  r.clearance = 0.3;
  const auto X = s.place(r);
  ASSERT_EQ(X.size(), 30u);
  EXPECT_FALSE(closest_foreign_nodes(s.grid, X, r.clearance).has_value());
  for (const auto& cell : X)
    for (const auto& p : cell) {
      EXPECT_GE(p.z, r.clearance);
      EXPECT_LE(p.z, 8 - r.clearance);
    }
  for (std::size_t a = 0; a < X.size(); ++a)
    for (std::size_t b = 0; b < X.size(); ++b)
      if (a != b) {
        EXPECT_FALSE(encloses(s.mesh, X[a], X[b][0])) << b << " in " << a;
      }
}

// The same seed gives bitwise the same placements; another seed others.
TEST(CellPacking, ASeedGivesTheSamePackingEveryTime) {
  const SphereBox s(Boundary::Periodic);
  PackingRequest r;
  r.count = 20;
  r.seed = 3;
  r.clearance = 0.3;
  const auto a = s.place(r), b = s.place(r);
  r.seed = 4;
  const auto c = s.place(r);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t k = 0; k < a[i].size(); ++k) {
      EXPECT_EQ(a[i][k].x, b[i][k].x);
      EXPECT_EQ(a[i][k].z, b[i][k].z);
    }
  EXPECT_NE(a[0][0].x, c[0][0].x);
}

// More spheres than fit (12 of radius 2 in a box of 512: volume fraction 0.79): one line naming the key and how far
// the packer got.
TEST(CellPacking, CopiesThatCannotFitAreRefusedWithTheFractionReached) {
  const SphereBox s(Boundary::Periodic);
  std::vector<Vec3> big;
  for (const auto& p : s.mesh.nodes) big.push_back(2 * p);
  PackingRequest r;
  r.count = 12;
  r.clearance = 0.6;
  try {
    CellPacking(s.grid, big, 2 * s.spacing, r, "packing.count");
    FAIL() << "12 spheres of radius 2 fitted in a box of 512";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("packing.count: the copies jam at "), 0u) << what;
    EXPECT_NE(what.find("(volume fraction reached: "), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// Nodes farther apart than the clearance allows are refused (a surface could cross another between them).
TEST(CellPacking, ACoarseTemplateIsRefused) {
  const SphereBox s(Boundary::Periodic);
  PackingRequest r;
  r.count = 2;
  r.clearance = 0.1;
  try {
    s.place(r);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("raise membrane[0].mesh.level"), std::string::npos) << e.what();
  }
}

// Red cells of eq. (45) (2,562 nodes, R0 = 3.91) at a volume fraction of 0.4 in a periodic box and between walls
// z = 0 and z = L: the copies have to turn to get there.
namespace {

struct Template {
  Mesh mesh;
  double spacing = 0, volume = 0;
};

Template red_cell() {
  Template t;
  t.mesh = icosahedral_sphere(3);
  const auto X = map_sphere(Shape{BiconcaveCell{}, {}}, t.mesh.nodes);
  const MembraneGeometry g = measure(t.mesh, X);
  for (std::size_t k = 0; k < X.size(); ++k) t.mesh.nodes[k] = X[k] - g.centroid;
  for (const auto& e : t.mesh.elements)
    for (const auto& [a, b] : {std::pair{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}})
      t.spacing = std::max(t.spacing, norm(t.mesh.nodes[e[a]] - t.mesh.nodes[e[b]]));
  t.volume = g.volume;
  return t;
}

std::vector<std::vector<Vec3>> nodes_of(const CellPacking& p, const Mesh& mesh) {
  std::vector<std::vector<Vec3>> X;
  for (const auto& t : p.placements()) {
    X.emplace_back();
    for (const auto& q : mesh.nodes) X.back().push_back(t.rotation * q + t.translation);
  }
  return X;
}

// No node pair of two copies within the clearance, no node within it of a wall; no node of one copy inside another
// (winding number) and no element of one crossing an element of another, periodic images included.
void expect_apart(const Grid& grid, const Mesh& mesh, const std::vector<std::vector<Vec3>>& X, double clearance) {
  EXPECT_FALSE(closest_foreign_nodes(grid, X, clearance).has_value());
  for (int a = 0; a < 3; ++a) {
    if (grid.periodic(a)) continue;
    for (const auto& cell : X)
      for (const auto& p : cell) {
        EXPECT_GE(p[a] - grid.origin()[a], clearance);
        EXPECT_GE(grid.origin()[a] + grid.length(a) - p[a], clearance);
      }
  }
  double R = 0;
  for (const auto& p : mesh.nodes) R = std::max(R, norm(p));
  std::vector<Vec3> centre;
  for (const auto& cell : X) centre.push_back(measure(mesh, cell).centroid);
  int near = 0;
  for (std::size_t a = 0; a < X.size(); ++a)
    for (std::size_t b = a + 1; b < X.size(); ++b)
      for (int i = -1; i <= 1; ++i)  // every periodic image of copy b that reaches copy a
        for (int j = -1; j <= 1; ++j)
          for (int k = -1; k <= 1; ++k) {
            const std::array<int, 3> image{i, j, k};
            Vec3 shift;
            bool exists = true;
            for (int d = 0; d < 3; ++d) {
              exists = exists && (grid.periodic(d) || image[d] == 0);
              shift[d] = image[d] * grid.length(d);
            }
            if (!exists || norm(centre[b] + shift - centre[a]) >= 2 * R) continue;
            ++near;
            std::vector<Vec3> moved;
            for (const auto& p : X[b]) moved.push_back(p + shift);
            for (std::size_t n = 0; n < moved.size(); ++n) {
              if (norm(moved[n] - centre[a]) < R) {
                EXPECT_FALSE(encloses(mesh, X[a], moved[n])) << b << ":" << n << " in " << a;
              }
              if (norm(X[a][n] - centre[b] - shift) < R) {
                EXPECT_FALSE(encloses(mesh, moved, X[a][n])) << a << ":" << n << " in " << b;
              }
            }
            Mesh both = mesh;
            both.nodes = X[a];
            both.nodes.insert(both.nodes.end(), moved.begin(), moved.end());
            const int offset = static_cast<int>(mesh.nodes.size());
            for (auto e : mesh.elements) {
              for (int& v : e) v += offset;
              both.elements.push_back(e);
            }
            EXPECT_FALSE(self_intersection(both, both.nodes).has_value()) << a << " and " << b;
          }
  EXPECT_GT(near, 0);  // the test met copies close enough to interlock
}

// Packs red cells at 0.4 in a cube of side L with the given boundary along z; checks and returns the nodes.
std::vector<std::vector<Vec3>> pack_red_cells(Boundary z, std::uint64_t seed) {
  const Template t = red_cell();
  const double L = 14.2, box = L * L * L;
  const Grid grid({16, 16, 16}, {L, L, L}, {Boundary::Periodic, Boundary::Periodic, z});
  PackingRequest r;
  r.count = static_cast<std::size_t>(std::llround(0.4 * box / t.volume));
  r.seed = seed;
  r.clearance = 1.25 * t.spacing;
  const CellPacking p(grid, t.mesh.nodes, t.spacing, r, "packing.volume_fraction");
  const auto X = nodes_of(p, t.mesh);
  EXPECT_EQ(X.size(), 12u);
  double fraction = 0;
  for (const auto& cell : X) fraction += measure(t.mesh, cell).volume / box;
  EXPECT_NEAR(fraction, 0.4, 0.5 * t.volume / box);  // the count rounded to whole cells
  expect_apart(grid, t.mesh, X, r.clearance);
  return X;
}

void expect_bitwise_equal(const std::vector<std::vector<Vec3>>& a, const std::vector<std::vector<Vec3>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t k = 0; k < a[i].size(); ++k) {
      EXPECT_EQ(a[i][k].x, b[i][k].x);
      EXPECT_EQ(a[i][k].y, b[i][k].y);
      EXPECT_EQ(a[i][k].z, b[i][k].z);
    }
}

}  // namespace

TEST(CellPacking, RedCellsReachFortyPercentInAPeriodicBox) {
  const auto a = pack_red_cells(Boundary::Periodic, 11);
  expect_bitwise_equal(a, pack_red_cells(Boundary::Periodic, 11));
}

TEST(CellPacking, RedCellsReachFortyPercentBetweenWalls) {
  const auto a = pack_red_cells(Boundary::Wall, 12);
  expect_bitwise_equal(a, pack_red_cells(Boundary::Wall, 12));
}

// Through the program: red cells at 10 % in a periodic box, one step; the header reports the packing; the run
// folder's configuration runs again to the same positions (the checkpoints agree bitwise).
TEST(CellPacking, APackedSuspensionRunsAndItsFolderRunsAgainAlike) {
  ScratchDir dir("packing");
  const std::string text = R"([domain]
Lx = 20e-6
Ly = 20e-6
Lz = 20e-6
[grid]
nx = 24
ny = 24
nz = 24
[fluid]
rho = 1025.0
mu = 1.2e-3
[time]
dt = 1e-5
end = 1e-5
[packing]
volume_fraction = 0.1
seed = 5
[[membrane]]
shape = "rbc"
mesh.level = 2
law = "yeoh"
C10 = 3.65e-6
C30 = 2.43e-7
)";
  std::ofstream(dir / "pack.toml") << text;
  const auto a = run_immerse(run_args(dir / "pack.toml", dir / "a", {}), dir / "a_run");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NE(a.out.find("# packing: 9 copies of membrane[0], volume fraction 0.1"), std::string::npos) << a.out;
  const auto b = run_immerse(run_args(dir / "a" / "config.resolved.toml", dir / "b", {}), dir / "b_run");
  ASSERT_EQ(b.status, 0) << b.err;
  const auto ca = io::Checkpoint::read(dir / "a" / "checkpoint.h5"), cb = io::Checkpoint::read(dir / "b" / "checkpoint.h5");
  for (int m = 0; m < 9; ++m) {
    const std::string name = "membrane[" + std::to_string(m) + "].positions";
    EXPECT_EQ(ca.array(name), cb.array(name)) << name;
  }
  const auto rows = read_csv(dir / "a" / "diagnostics.csv");
  EXPECT_NE(std::find(rows[0].begin(), rows[0].end(), "m8_theta"), rows[0].end());
  EXPECT_NE(std::find(rows[0].begin(), rows[0].end(), "m8_E_elastic"), rows[0].end());
  EXPECT_EQ(rows[0].back(), "budget_residual");

  // Keys that contradict the packing: one line naming them, status 2, nothing written.
  for (const std::vector<std::string>& sets :
       {std::vector<std::string>{"packing.count=4"}, {"membrane[0].rotation_angle=0.5"}}) {
    const auto bad = run_immerse(run_args(dir / "pack.toml", dir / "bad", sets), dir / "bad_run");
    EXPECT_EQ(bad.status, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_FALSE(fs::exists(dir / "bad"));
  }
}
