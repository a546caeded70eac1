// CellPacking: copies of one membrane at random positions and orientations with no two closer than the clearance,
// reproducible by seed; through the program, [packing] fills the box to the volume fraction asked for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "immerse/core/Error.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/simulation/CellPacking.hpp"
#include "immerse/simulation/MembraneClearance.hpp"
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
    EXPECT_NE(std::string(e.what()).find("packing.count: the copies jam at "), std::string::npos) << e.what();
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
  EXPECT_EQ(rows[0].back(), "m8_theta");

  // Keys that contradict the packing: one line naming them, status 2, nothing written.
  for (const std::vector<std::string>& sets :
       {std::vector<std::string>{"packing.count=4"}, {"membrane[0].rotation_angle=0.5"}}) {
    const auto bad = run_immerse(run_args(dir / "pack.toml", dir / "bad", sets), dir / "bad_run");
    EXPECT_EQ(bad.status, 2) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_FALSE(fs::exists(dir / "bad"));
  }
}
