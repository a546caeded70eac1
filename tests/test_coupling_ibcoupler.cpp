// Force spreading (eq. 6) and velocity interpolation (eq. 14) on the MAC grid: against a direct
// evaluation of the sums, thread independence, behaviour at walls, node diagnostics, allocations.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <random>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"

// Count every operator new of this program, to show that spreading and interpolation do not
// allocate once warmed up. new and delete are replaced together (malloc/free), which GCC cannot
// see across inlining.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<long> allocations{0};
}
void* operator new(std::size_t size) {
  ++allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;

std::vector<Vec3> random_nodes(const Grid& g, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> X(count);
  for (auto& x : X)
    for (int a = 0; a < 3; ++a) x[a] = g.origin()[a] + unit(rng) * g.length(a);
  return X;
}

std::vector<Vec3> random_vectors(int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Vec3> F(count);
  for (auto& f : F) f = {normal(rng), normal(rng), normal(rng)};
  return F;
}

/// D_h(x − X) summed over the periodic images of X (eq. 7), by direct evaluation.
double delta_with_images(const Grid& g, const DeltaKernel& k, const Vec3& x, const Vec3& X) {
  double sum = 0;
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c) {
        const int shift[3] = {a, b, c};
        bool skip = false;
        Vec3 image = X;
        for (int e = 0; e < 3; ++e) {
          if (shift[e] != 0 && !g.periodic(e)) skip = true;
          image[e] += shift[e] * g.length(e);
        }
        if (!skip) sum += delta_h(k, x - image, g.h());
      }
  return sum;
}

/// Nodes of a sphere (Fibonacci lattice) of radius R about c.
std::vector<Vec3> sphere_nodes(int count, Vec3 c, double R) {
  std::vector<Vec3> X(count);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int l = 0; l < count; ++l) {
    const double z = 1.0 - 2.0 * (l + 0.5) / count, r = std::sqrt(1.0 - z * z);
    X[l] = c + R * Vec3{r * std::cos(golden * l), r * std::sin(golden * l), z};
  }
  return X;
}

}  // namespace

TEST(IBCoupler, SpreadingAndInterpolationEqualTheSumsOfEqs6And14) {
  // Each component on its own faces; periodic images on periodic axes; nodes near the seam and walls.
  for (const auto& bc : {std::array{P, P, P}, std::array{W, P, W}, std::array{P, W, W}}) {
    const Grid g({6, 8, 5}, {0.6, 0.8, 0.5}, bc, {0.1, -0.2, 0.3});
    auto X = random_nodes(g, 6, 1);
    X[0] = g.origin() + Vec3{1e-9, 0.79999, 0.02};  // at the seam / next to walls
    X[1] = g.origin() + Vec3{g.length(0), 0.0, g.length(2)};  // on the far walls / the seam
    const auto F = random_vectors(6, 2);
    for (const auto& kernel : {DeltaKernel{RomaPeskin3{}}, DeltaKernel{Peskin4{}}}) {
      IBCoupler coupler(g, kernel);
      FaceField f(g), u(g);
      coupler.spread_force(X, F, f);
      double spread_error = 0, scale = 0;
      for (int d = 0; d < 3; ++d) {
        const auto s = g.face_shape(d);
        for (int k = 0; k < s[2]; ++k)
          for (int j = 0; j < s[1]; ++j)
            for (int i = 0; i < s[0]; ++i) {
              const Vec3 x = g.face_position(d, i, j, k);
              double direct = 0;
              for (std::size_t l = 0; l < X.size(); ++l) direct += F[l][d] * delta_with_images(g, kernel, x, X[l]);
              spread_error = std::fmax(spread_error, std::abs(f[d](i, j, k) - direct));
              scale = std::fmax(scale, std::abs(direct));
              u[d](i, j, k) = std::sin(3 * x.x + d) * std::cos(2 * x.y - x.z);
            }
      }
      EXPECT_LE(spread_error, 1e-13 * scale) << kernel_name(kernel);

      std::vector<Vec3> U(X.size());
      coupler.interpolate_velocity(u, X, U);
      double interp_error = 0;
      for (std::size_t l = 0; l < X.size(); ++l)
        for (int d = 0; d < 3; ++d) {
          double direct = 0;
          const auto s = g.face_shape(d);
          for (int k = 0; k < s[2]; ++k)
            for (int j = 0; j < s[1]; ++j)
              for (int i = 0; i < s[0]; ++i)
                direct += u[d](i, j, k) * delta_with_images(g, kernel, g.face_position(d, i, j, k), X[l]) *
                          g.cell_volume();
          interp_error = std::fmax(interp_error, std::abs(U[l][d] - direct));
        }
      EXPECT_LE(interp_error, 1e-14) << kernel_name(kernel);
    }
  }
}

TEST(IBCoupler, SpreadingIsBitwiseIdenticalWithOneAndTwoThreads) {
  const Grid g({32, 32, 32}, {1, 1, 1}, {P, W, P});
  auto X = sphere_nodes(10242, {0.5, 0.5, 0.5}, 0.3);
  const auto more = random_nodes(g, 2000, 3);  // also across the seam and near the walls
  X.insert(X.end(), more.begin(), more.end());
  const auto F = random_vectors(static_cast<int>(X.size()), 4);
  std::vector<Vec3> U1(X.size()), U2(X.size());
  FaceField f1(g), f2(g);
  const int threads = omp_get_max_threads();
  IBCoupler coupler(g, RomaPeskin3{});
  omp_set_num_threads(1);
  coupler.spread_force(X, F, f1);
  coupler.interpolate_velocity(f1, X, U1);
  omp_set_num_threads(2);
  coupler.spread_force(X, F, f2);
  coupler.interpolate_velocity(f2, X, U2);
  omp_set_num_threads(threads);
  for (int d = 0; d < 3; ++d)
    EXPECT_EQ(std::memcmp(f1[d].data(), f2[d].data(), f1[d].size() * sizeof(double)), 0) << "component " << d;
  EXPECT_EQ(std::memcmp(U1.data(), U2.data(), U1.size() * sizeof(Vec3)), 0);
}

TEST(IBCoupler, SeveralMembranesSpreadAsTheirSum) {
  const Grid g({16, 16, 16}, {1, 1, 1}, {P, P, W});
  const auto A = sphere_nodes(642, {0.3, 0.5, 0.5}, 0.15), B = sphere_nodes(642, {0.7, 0.5, 0.5}, 0.15);
  std::vector<Vec3> AB = A;
  AB.insert(AB.end(), B.begin(), B.end());
  const auto F = random_vectors(1284, 5);
  const std::vector<Vec3> FA(F.begin(), F.begin() + 642), FB(F.begin() + 642, F.end());
  IBCoupler coupler(g);
  FaceField fa(g), fb(g), fab(g);
  coupler.spread_force(A, FA, fa);
  coupler.spread_force(B, FB, fb);
  coupler.spread_force(AB, F, fab);
  double e = 0, scale = 0;
  for (int d = 0; d < 3; ++d)
    for (std::size_t p = 0; p < fab[d].size(); ++p) {
      e = std::fmax(e, std::abs(fab[d][p] - fa[d][p] - fb[d][p]));
      scale = std::fmax(scale, std::abs(fab[d][p]));
    }
  EXPECT_LE(e, 1e-14 * scale);
}

TEST(IBCoupler, MomentsHoldExactlyOutsideTheKernelReachOfAWall) {
  // Points beyond a wall are dropped: the stored total force is exact for distance >= (support - 1/2) h,
  // the force on the fluid (wall faces excluded) for distance >= support h; closer, force is lost.
  const Grid g({8, 8, 8}, {1, 1, 1}, {P, P, W});
  const double h = g.h();
  const Vec3 F{0.2, -0.5, 0.8};
  for (const auto& kernel : {DeltaKernel{RomaPeskin3{}}, DeltaKernel{Peskin4{}}}) {
    IBCoupler coupler(g, kernel);
    const double support = kernel_support(kernel);
    FaceField f(g);
    auto totals = [&](double distance, Vec3& stored, Vec3& fluid) {
      const Vec3 X[1] = {{0.37, 0.61, distance}}, Fs[1] = {F};
      coupler.spread_force(X, Fs, f);
      stored = fluid = Vec3{};
      for (int d = 0; d < 3; ++d) {
        const auto s = g.face_shape(d);
        for (int k = 0; k < s[2]; ++k)
          for (int j = 0; j < s[1]; ++j)
            for (int i = 0; i < s[0]; ++i) {
              stored[d] += f[d](i, j, k) * g.cell_volume();
              if (!(d == 2 && (k == 0 || k == s[2] - 1))) fluid[d] += f[d](i, j, k) * g.cell_volume();
            }
      }
    };
    Vec3 stored, fluid;
    totals((support - 0.5) * h, stored, fluid);
    EXPECT_LE(norm(stored - F), 1e-15) << kernel_name(kernel);
    totals(support * h, stored, fluid);
    EXPECT_LE(norm(fluid - F), 1e-15) << kernel_name(kernel);
    totals(0.25 * h, stored, fluid);
    const double lost = norm(stored - F) / norm(F);
    std::cout << kernel_name(kernel) << ": node at h/4 from a wall loses " << lost
              << " of its force from the stored field, " << norm(fluid - F) / norm(F) << " from the fluid\n";
    EXPECT_GT(lost, 0.01);

    // Interpolating a uniform field returns it exactly only outside the same reach.
    FaceField u(g);
    u.fill(1.0);
    std::vector<Vec3> U(2);
    const std::vector<Vec3> X{{0.37, 0.61, (support - 0.5) * h}, {0.37, 0.61, 0.25 * h}};
    coupler.interpolate_velocity(u, X, U);
    EXPECT_LE(norm(U[0] - Vec3{1, 1, 1}), 1e-15);
    EXPECT_GT(norm(U[1] - Vec3{1, 1, 1}), 0.01);
  }
}

TEST(IBCoupler, NodesBeyondAWallOrNonFiniteAreNamed) {
  const Grid g({8, 8, 8}, {1, 1, 1}, {P, W, P});
  IBCoupler coupler(g);
  FaceField f(g);
  std::vector<Vec3> X = random_nodes(g, 10, 6), F(10);
  X[7].y = 1.0 + 1e-9;
  try {
    coupler.spread_force(X, F, f);
    FAIL() << "no SimulationError";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("node 7 "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("beyond the wall y = 1"), std::string::npos) << e.what();
  }
  X[7].y = 0.5;
  X[3].x = NAN;
  std::vector<Vec3> U(10);
  EXPECT_THROW(coupler.interpolate_velocity(f, X, U), SimulationError);
  EXPECT_THROW(min_wall_distance(g, X), SimulationError);
  X[3].x = -17.25;  // periodic axis: wraps
  EXPECT_NO_THROW(coupler.spread_force(X, F, f));
  X[3].x = 1e300;  // still finite: wraps too
  EXPECT_NO_THROW(coupler.interpolate_velocity(f, X, U));
}

TEST(IBCoupler, NodesWholePeriodsApartAreTheSameNode) {
  const Grid g({8, 8, 8}, {1, 1, 1}, {P, P, W});
  IBCoupler coupler(g);
  FaceField f1(g), f2(g);
  const std::vector<Vec3> X1{{0.3125, 0.7, 0.4}}, X2{{0.3125 + 5.0, 0.7 - 3.0, 0.4}}, F{{1, 2, 3}};
  coupler.spread_force(X1, F, f1);
  coupler.spread_force(X2, F, f2);
  for (int d = 0; d < 3; ++d)
    for (std::size_t p = 0; p < f1[d].size(); ++p) EXPECT_NEAR(f1[d][p], f2[d][p], 1e-12) << d << " " << p;
}

TEST(NodeDiagnostics, MinWallDistance) {
  const std::vector<Vec3> X{{0.5, 0.5, 0.5}, {0.9, 0.03, 0.5}, {5.0, 0.5, 0.96}};
  EXPECT_DOUBLE_EQ(min_wall_distance(Grid({4, 4, 4}, {1, 1, 1}, {P, W, W}), X), 0.03);
  EXPECT_NEAR(min_wall_distance(Grid({4, 4, 4}, {1, 1, 1}, {P, P, W}), X), 0.04, 1e-15);
  EXPECT_EQ(min_wall_distance(Grid({4, 4, 4}, {1, 1, 1}, {P, P, P}), X), INFINITY);
}

TEST(IBCoupler, NoAllocationOnceWarmedUp) {
  const Grid g({16, 16, 16}, {1, 1, 1}, {P, W, P});
  const auto X = sphere_nodes(2562, {0.5, 0.5, 0.5}, 0.3);
  const auto F = random_vectors(2562, 7);
  std::vector<Vec3> U(X.size());
  FaceField f(g);
  IBCoupler coupler(g, Peskin4{});
  coupler.spread_force(X, F, f);
  coupler.interpolate_velocity(f, X, U);
  const long before = allocations.load();
  for (int step = 0; step < 3; ++step) {
    coupler.spread_force(X, F, f);
    coupler.interpolate_velocity(f, X, U);
  }
  EXPECT_EQ(allocations.load() - before, 0);
}
