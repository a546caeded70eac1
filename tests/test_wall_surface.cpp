// Walls given as closed surface meshes (WallSurface, shape = "surface"): STL ASCII, STL binary and Gmsh files read
// into the exact signed distance of a cube and, within the chord error, of a sphere; signs, normals, periodic images
// (a solid and a fluid-filled surface) through WallGeometry, each defect refused with one line, the configuration keys,
// and the surface sphere against the analytic Sphere shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/walls/WallGeometry.hpp"
#include "immerse/walls/WallSurface.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr Boundary P = Boundary::Periodic;

struct Tri {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
};

// The cube [c − a, c + a]³, 12 triangles counter-clockwise seen from outside.
Tri cube(const Vec3& c, const Vec3& a) {
  Tri s;
  for (int i = 0; i < 8; ++i)
    s.v.push_back(c + Vec3{(i & 1 ? 1 : -1) * a.x, (i & 2 ? 1 : -1) * a.y, (i & 4 ? 1 : -1) * a.z});
  for (const auto& q : std::vector<std::array<int, 4>>{
           {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}) {
    s.t.push_back({q[0], q[1], q[2]});
    s.t.push_back({q[0], q[2], q[3]});
  }
  return s;
}

// The corners of the project's icosahedral sphere of `level` (20·4^level flat triangles), radius R about c.
Tri icosphere(int level, double R, const Vec3& c = {}) {
  const Mesh m = icosahedral_sphere(level);
  Tri s;
  std::vector<int> index(m.nodes.size(), -1);
  for (const auto& el : m.elements) {
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      if (index[el[k]] < 0)
        index[el[k]] = static_cast<int>(s.v.size()), s.v.push_back(c + R * normalized(m.nodes[el[k]]));
      t[k] = index[el[k]];
    }
    s.t.push_back(t);
  }
  return s;
}

// The chord error: how far inside the sphere of radius R about c the flat triangles reach (their planes' distances).
double chord_error(const Tri& s, double R, const Vec3& c = {}) {
  double nearest = R;
  for (const auto& t : s.t) {
    const Vec3 n = normalized(cross(s.v[t[1]] - s.v[t[0]], s.v[t[2]] - s.v[t[0]]));
    nearest = std::min(nearest, std::abs(dot(n, s.v[t[0]] - c)));
  }
  return R - nearest;
}

void write_stl_ascii(const fs::path& path, const Tri& s) {
  std::ofstream f(path);
  f.precision(17);
  f << "solid test\n";
  for (const auto& t : s.t) {
    f << "  facet normal 0 0 0\n    outer loop\n";
    for (int k = 0; k < 3; ++k) f << "      vertex " << s.v[t[k]].x << " " << s.v[t[k]].y << " " << s.v[t[k]].z << "\n";
    f << "    endloop\n  endfacet\n";
  }
  f << "endsolid test\n";
}

std::string stl_binary(const Tri& s) {
  std::string b(80, ' ');
  b.replace(0, 11, "solid  test");  // a header starting with "solid", as some programs write
  const auto put32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  put32(static_cast<std::uint32_t>(s.t.size()));
  for (const auto& t : s.t) {
    for (int k = 0; k < 3; ++k) put32(0);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) put32(std::bit_cast<std::uint32_t>(static_cast<float>(s.v[t[k]][a])));
    b += std::string(2, '\0');
  }
  return b;
}

void write_bytes(const fs::path& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// The exact signed distance to the box [c − a, c + a].
double box_distance(const Vec3& x, const Vec3& c, const Vec3& a) {
  Vec3 q;
  for (int k = 0; k < 3; ++k) q[k] = std::abs(x[k] - c[k]) - a[k];
  const Vec3 out{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
  return norm(out) + std::min(std::max({q.x, q.y, q.z}), 0.0);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Points of a pseudo-random but fixed cloud in [lo, hi].
std::vector<Vec3> cloud(std::size_t n, const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> p;
  std::uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (std::size_t i = 0; i < n; ++i) p.push_back({lo.x + (hi.x - lo.x) * next(), lo.y + (hi.y - lo.y) * next(),
                                                   lo.z + (hi.z - lo.z) * next()});
  return p;
}

WallShape surface_shape(const WallSurface& s, bool fluid_inside) {
  WallShape w;
  w.kind = WallShape::Kind::Surface;
  w.surface = std::make_shared<const WallSurface>(s);
  w.fluid_inside = fluid_inside;
  w.name = "wall[0]";
  return w;
}

}  // namespace

TEST(WallSurface, CubeFromAsciiStlHasTheExactSignedDistanceAndNormals) {
  ScratchDir dir("wall_surface");
  const Vec3 c{1, 2, 3}, a{0.5, 0.25, 1};
  write_stl_ascii(dir / "cube.stl", cube(c, a));
  const WallSurface s = read_wall_surface(dir / "cube.stl", 1e-6, "wall[0].file");  // the file in micrometres
  EXPECT_EQ(s.vertices().size(), 8u);
  EXPECT_EQ(s.triangles().size(), 12u);
  EXPECT_NEAR(s.volume(), 8 * a.x * a.y * a.z * 1e-18, 1e-30);
  double worst = 0;
  for (const Vec3& x : cloud(20000, {-1, 0, 0}, {3, 4, 6}))
    worst = std::max(worst, std::abs(s.distance(1e-6 * x) - 1e-6 * box_distance(x, c, a)));
  EXPECT_LE(worst, 1e-20);
  // Normals: out of the nearest face inside and outside, from the nearest corner or edge outside.
  const auto near = [](const Vec3& u, const Vec3& v) { return norm(u - v) < 1e-12; };
  EXPECT_TRUE(near(s.normal(1e-6 * Vec3{1.6, 2, 3}), {1, 0, 0}));
  EXPECT_TRUE(near(s.normal(1e-6 * Vec3{1.4, 2, 3.1}), {1, 0, 0}));  // inside, nearest the face x = 1.5
  EXPECT_TRUE(near(s.normal(1e-6 * Vec3{1, 1.9, 3}), {0, -1, 0}));
  EXPECT_TRUE(near(s.normal(1e-6 * Vec3{2.5, 3.25, 5}), normalized(Vec3{1, 1, 1})));  // the corner (1.5, 2.25, 4)
  EXPECT_TRUE(near(s.normal(1e-6 * Vec3{2.5, 3.25, 3}), normalized(Vec3{1, 1, 0})));  // the edge x = 1.5, y = 2.25
  EXPECT_LT(s.distance(1e-6 * c), 0);
  // An inward-oriented file is turned outward: the same distances.
  Tri inward = cube(c, a);
  for (auto& t : inward.t) std::swap(t[1], t[2]);
  write_stl_ascii(dir / "inward.stl", inward);
  const WallSurface flipped = read_wall_surface(dir / "inward.stl", 1e-6, "wall[0].file");
  EXPECT_DOUBLE_EQ(flipped.distance(1e-6 * Vec3{1.6, 2, 3}), s.distance(1e-6 * Vec3{1.6, 2, 3}));
  EXPECT_NEAR(flipped.distance(1e-6 * c), -0.25e-6, 1e-21);
}

TEST(WallSurface, SphereFromBinaryStlWithinTheChordError) {
  ScratchDir dir("wall_surface");
  const Tri ico = icosphere(3, 1.0);
  write_bytes(dir / "sphere.stl", stl_binary(ico));
  const WallSurface s = read_wall_surface(dir / "sphere.stl", 2.0, "wall[0].file");
  EXPECT_EQ(s.triangles().size(), 1280u);
  EXPECT_EQ(s.vertices().size(), 642u);  // merged by exact equality of the (float) coordinates
  const double delta = 2 * chord_error(ico, 1.0) + 1e-6;  // and float rounding
  std::printf("chord error of the level-3 icosphere: %.4g of the radius\n", delta / 2);
  double worst = 0;
  int inside = 0;
  for (const Vec3& x : cloud(20000, {-3, -3, -3}, {3, 3, 3})) {
    const double d = s.distance(x), exact = norm(x) - 2;
    worst = std::max(worst, std::abs(d - exact));
    if (std::abs(exact) > delta) {
      EXPECT_EQ(d < 0, exact < 0) << x.x << " " << x.y << " " << x.z;
      inside += exact < 0;
      // Outside, away from the surface, the normal is within the chord's angle of the radial direction.
      if (exact > 0.2) {
        EXPECT_GT(dot(s.normal(x), normalized(x)), 0.99);
      }
    }
  }
  EXPECT_LE(worst, delta);
  EXPECT_GT(inside, 500);
  EXPECT_NEAR(s.volume(), 4.0 / 3 * std::numbers::pi * 8, 0.02 * 4.0 / 3 * std::numbers::pi * 8);
}

TEST(WallSurface, GmshSurfaceKeepsTheCornersOfItsSixNodeTriangles) {
  ScratchDir dir("wall_surface");
  const Mesh m = icosahedral_sphere(2);
  write_gmsh(dir / "sphere.msh", m);
  const WallSurface s = read_wall_surface(dir / "sphere.msh", 1.0, "wall[2].file");
  EXPECT_EQ(s.triangles().size(), m.elements.size());
  EXPECT_EQ(s.vertices().size(), 162u);  // the corners only
  const double delta = chord_error(icosphere(2, 1.0), 1.0) + 1e-12;
  for (const Vec3& x : cloud(5000, {-2, -2, -2}, {2, 2, 2})) EXPECT_LE(std::abs(s.distance(x) - (norm(x) - 1)), delta);
  // The reader's own defects name the wall.
  write_gmsh(dir / "open.msh", Mesh{m.nodes, {m.elements.begin() + 1, m.elements.end()}});
  EXPECT_EQ(error_of([&] { read_wall_surface(dir / "open.msh", 1.0, "wall[2].file"); }).rfind("wall[2].file: mesh ", 0),
            0u);
}

TEST(WallSurface, RefusesEveryDefectWithOneLine) {
  ScratchDir dir("wall_surface");
  const auto message = [&](const std::string& name, const Tri& s) {
    write_stl_ascii(dir / name, s);
    const std::string e = error_of([&] { read_wall_surface(dir / name, 1.0, "wall[1].file"); });
    EXPECT_EQ(e.find('\n'), std::string::npos);
    EXPECT_EQ(e.rfind("wall[1].file " + (dir / name).string() + ": ", 0), 0u) << e;
    return e;
  };
  const Tri good = cube({0, 0, 0}, {1, 1, 1});
  Tri open = good;
  open.t.pop_back();
  EXPECT_NE(message("open.stl", open)
                .find("the surface is open: edge [1, -1, 1] - [1, 1, 1] of triangle 2 belongs to no other triangle"),
            std::string::npos);
  Tri turned = good;
  std::swap(turned.t[5][1], turned.t[5][2]);
  EXPECT_NE(message("turned.stl", turned).find("are oriented inconsistently: both run edge"), std::string::npos);
  Tri zero = good;
  zero.t.push_back({0, 0, 1});
  EXPECT_NE(message("zero.stl", zero)
                .find("triangle 12 (corners [-1, -1, -1], [-1, -1, -1], [1, -1, -1]) has zero area"),
            std::string::npos);
  Tri two = good;  // two cubes crossing each other: closed and oriented, but not one non-intersecting surface
  const Tri other = cube({0.5, 0.3, 0.2}, {1, 1, 1});
  for (auto t : other.t) {
    for (int& i : t) i += 8;
    two.t.push_back(t);
  }
  two.v.insert(two.v.end(), other.v.begin(), other.v.end());
  EXPECT_NE(message("crossing.stl", two).find("intersect: the surface crosses itself"), std::string::npos);
  Tri fin = good;  // a fin of two triangles on an edge of the cube: that edge in four triangles
  fin.v.push_back({0, -3, -3});
  fin.t.push_back({0, 1, 8});
  fin.t.push_back({1, 0, 8});
  EXPECT_NE(message("fin.stl", fin).find("is shared by 4 triangles: must be two"), std::string::npos);
  // A binary file of the wrong size, an empty file, a missing file, a file of no triangles.
  std::string bytes = stl_binary(good);
  write_bytes(dir / "short.stl", bytes.substr(0, bytes.size() - 1));
  EXPECT_EQ(error_of([&] { read_wall_surface(dir / "short.stl", 1.0, "wall[1].file"); }),
            "wall[1].file " + (dir / "short.stl").string() +
                ": a binary STL of 12 triangles (its count at byte 80) has 684 bytes, the file 683 (truncated, or "
                "not an STL file)");
  write_bytes(dir / "empty.stl", "");
  EXPECT_EQ(error_of([&] { read_wall_surface(dir / "empty.stl", 1.0, "wall[1].file"); }),
            "wall[1].file " + (dir / "empty.stl").string() + ": the file is empty");
  EXPECT_EQ(error_of([&] { read_wall_surface(dir / "missing.stl", 1.0, "wall[1].file"); }),
            "wall[1].file " + (dir / "missing.stl").string() + ": cannot read the file");
  write_bytes(dir / "none.stl", "solid nothing\nendsolid nothing\n");
  EXPECT_NE(error_of([&] { read_wall_surface(dir / "none.stl", 1.0, "wall[1].file"); }).find("holds no triangles"),
            std::string::npos);
  write_bytes(dir / "typo.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n");
  EXPECT_NE(error_of([&] { read_wall_surface(dir / "typo.stl", 1.0, "wall[1].file"); })
                .find(": line 4 \"vertex 0 0 zero\": a coordinate is not a number"),
            std::string::npos);
  // A surface outside the box.
  const Grid g({8, 8, 8}, {4.0, 4.0, 4.0}, {P, P, P});
  const WallSurface far(cube({10, 10, 10}, {0.5, 0.5, 0.5}).v, cube({10, 10, 10}, {0.5, 0.5, 0.5}).t, "far");
  EXPECT_EQ(error_of([&] { WallGeometry({surface_shape(far, false)}, g); }),
            "wall[0]: the surface (bounding box [9.5, 9.5, 9.5] to [10.5, 10.5, 10.5]) lies outside the box [0, 0, 0] "
            "to [4, 4, 4] (is the file in another unit? scale converts it to metres)");
}

// A solid cube across the periodic boundary x = 0, and a fluid-filled duct longer than the box whose images make one
// endless channel: φ against the exact distances to the images.
TEST(WallSurface, PeriodicImagesOfASolidAndOfAFluidFilledSurface) {
  const Grid g({8, 8, 8}, {2.0, 2.0, 2.0}, {P, P, P});
  const Vec3 c{0.1, 1, 1}, a{0.3, 0.3, 0.3};
  const Tri box = cube(c, a);
  const WallGeometry solid({surface_shape(WallSurface(box.v, box.t, "cube"), false)}, g);
  EXPECT_NEAR(solid.distance({1.7, 1, 1}), 0.1, 1e-14);   // the image's face x = 1.8
  EXPECT_NEAR(solid.normal({1.7, 1, 1}).x, -1.0, 1e-14);  // into the fluid, away from the image
  EXPECT_NEAR(solid.distance({1.9, 1, 1}), -0.1, 1e-14);  // inside the image
  double worst = 0;
  for (const Vec3& x : cloud(20000, {0, 0, 0}, {2, 2, 2})) {
    double exact = 1e9;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) exact = std::min(exact, box_distance(x, c + Vec3{2.0 * i, 2.0 * j, 2.0 * k}, a));
    worst = std::max(worst, std::abs(solid.distance(x) - exact));
  }
  EXPECT_LE(worst, 1e-14);
  // The same cube holding the fluid: φ = −d.
  const WallGeometry cell({surface_shape(WallSurface(box.v, box.t, "cube"), true)}, g);
  EXPECT_NEAR(cell.distance(c), 0.3, 1e-14);
  EXPECT_NEAR(cell.distance({1.1, 1, 1}), -0.7, 1e-14);
  EXPECT_NEAR(cell.normal({0.3, 1, 1}).x, -1.0, 1e-14);  // into the fluid, away from the face x = 0.4
  // A duct x in [−0.5, 2.5], |y − 1|, |z − 1| < 0.5: its ends lie in its images, the fluid is the endless duct.
  const Tri duct = cube({1, 1, 1}, {1.5, 0.5, 0.5});
  const WallGeometry channel({surface_shape(WallSurface(duct.v, duct.t, "duct"), true)}, g);
  for (const Vec3& x : cloud(20000, {0, 0, 0}, {2, 2, 2})) {
    const double exact = 0.5 - std::max(std::abs(x.y - 1), std::abs(x.z - 1));
    const double outside = std::hypot(std::max(std::abs(x.y - 1) - 0.5, 0.0), std::max(std::abs(x.z - 1) - 0.5, 0.0));
    ASSERT_NEAR(channel.distance(x), exact > 0 ? exact : -outside, 1e-14) << x.x << " " << x.y << " " << x.z;
  }
}

TEST(WallSurface, SphereAsSurfaceMatchesTheAnalyticSphereWithinTheChordError) {
  ScratchDir dir("wall_surface");
  const Grid g({16, 16, 16}, {2e-6, 2e-6, 2e-6}, {P, P, P});
  const Vec3 c{1.0, 1.0, 1.9};  // near the boundary z = 2: the images count
  const double R = 0.5;
  const Tri ico = icosphere(3, R, c);
  write_stl_ascii(dir / "ball.stl", ico);
  WallShape ball = surface_shape(read_wall_surface(dir / "ball.stl", 1e-6, "wall[0].file"), false);
  WallShape exact{WallShape::Kind::Sphere, 1e-6 * c, {}, 1e-6 * R, 0, "wall[0]"};
  const WallGeometry surface({ball}, g), analytic({exact}, g);
  const double delta = 1e-6 * chord_error(ico, R, c) * (1 + 1e-9);
  std::printf("chord error: %.4g m (R = %g m)\n", delta, 1e-6 * R);
  double worst = 0;
  for (const Vec3& x : cloud(50000, {0, 0, 0}, {2e-6, 2e-6, 2e-6})) {
    worst = std::max(worst, std::abs(surface.distance(x) - analytic.distance(x)));
    if (analytic.distance(x) > 0.2e-6) {
      EXPECT_GT(dot(surface.normal(x), analytic.normal(x)), 0.99);
    }
  }
  EXPECT_LE(worst, delta + 1e-20);
  EXPECT_GT(worst, 0.1 * delta);  // the check would see a larger error
}

// φ of a 20,480-triangle surface through its bounding-volume hierarchy: the same as by brute force (its speed is
// bench/bench_walls.cpp's BM_WallSurfaceDistance).
TEST(WallSurface, FineSurfaceDistanceEqualsBruteForce) {
  const Tri ico = icosphere(5, 0.6, {1, 1, 1});
  const WallSurface s(ico.v, ico.t, "sphere");
  for (const Vec3& x : cloud(200, {0.5, 0.5, 0.5}, {1.5, 1.5, 1.5})) {
    double brute = 1e9;
    for (const auto& t : ico.t) {
      // The distance to a triangle: its plane if the foot is inside it, else the nearest edge.
      const Vec3 a = ico.v[t[0]], b = ico.v[t[1]], cc = ico.v[t[2]];
      const Vec3 n = normalized(cross(b - a, cc - a));
      const Vec3 foot = x - dot(x - a, n) * n;
      const bool in = dot(cross(b - a, foot - a), n) >= 0 && dot(cross(cc - b, foot - b), n) >= 0 &&
                      dot(cross(a - cc, foot - cc), n) >= 0;
      double d = in ? std::abs(dot(x - a, n)) : 1e9;
      for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, cc}, std::pair{cc, a}}) {
        const double u = std::clamp(dot(x - p, q - p) / dot(q - p, q - p), 0.0, 1.0);
        d = std::min(d, norm(x - (p + u * (q - p))));
      }
      brute = std::min(brute, d);
    }
    EXPECT_NEAR(std::abs(s.distance(x)), brute, 1e-14);
    if (const double r = norm(x - Vec3{1, 1, 1}); std::abs(r - 0.6) > 1e-3) {
      EXPECT_EQ(s.distance(x) < 0, r < 0.6);
    }
  }
}

// [[wall]] shape = "surface": the file found from the configuration's folder, scale and inside; keys that do not apply
// refused.
TEST(WallSurface, ConfigurationBuildsTheSurfaceWall) {
  ScratchDir dir("wall_surface");
  write_stl_ascii(dir / "cube.stl", cube({1, 1, 1}, {0.25, 0.25, 0.25}));
  const auto toml = [](const std::string& wall) {
    return "[domain]\nLx = 2e-6\nLy = 2e-6\nLz = 2e-6\n[grid]\nnx = 8\nny = 8\nnz = 8\n[[wall]]\n" + wall;
  };
  const io::ConfigSchema schema = run_schema();
  const auto parse = [&](const std::string& wall) {
    std::ofstream(dir / "run.toml") << toml(wall);
    return apply_scenario(schema.parse_file(dir / "run.toml"));
  };
  const io::Config c = parse("shape = \"surface\"\nfile = \"cube.stl\"\nscale = 1e-6\n");
  EXPECT_TRUE(fs::equivalent(c.entry("wall", 0).get<std::string>("file"), dir / "cube.stl"));
  const FluidParams p = run_fluid_params(c);
  ASSERT_TRUE(p.walls);
  EXPECT_NEAR(p.walls->distance({1e-6, 1e-6, 1e-6}), -0.25e-6, 1e-21);
  EXPECT_NEAR(p.walls->distance({1.5e-6, 1e-6, 1e-6}), 0.25e-6, 1e-21);
  const FluidParams q =
      run_fluid_params(parse("shape = \"surface\"\nfile = \"cube.stl\"\nscale = 1e-6\ninside = \"fluid\"\n"));
  EXPECT_NEAR(q.walls->distance({1e-6, 1e-6, 1e-6}), 0.25e-6, 1e-21);
  EXPECT_EQ(error_of([&] { parse("shape = \"surface\"\nfile = \"cube.stl\"\nradius = 1e-6\n"); }),
            "wall[0].radius: does not apply to shape = \"surface\" (its keys: file, inside, scale)");
  EXPECT_EQ(error_of([&] { parse("shape = \"tube\"\nradius = 0.5e-6\nfile = \"a.stl\"\n"); }),
            "wall[0].file: does not apply to shape = \"tube\" (its keys: axis, center, radius)");
  EXPECT_EQ(error_of([&] { parse("shape = \"surface\"\n"); }),
            "wall[0].file: must be given (an STL or Gmsh file name) when shape = \"surface\"");
  // In micrometres without scale: outside the box.
  EXPECT_NE(error_of([&] { run_fluid_params(parse("shape = \"surface\"\nfile = \"cube.stl\"\n")); })
                .find("wall[0]: the surface (bounding box [0.75, 0.75, 0.75] to [1.25, 1.25, 1.25]) lies outside"),
            std::string::npos);
}
