// Walls of any shape: the signed distance of the analytic shapes (WallGeometry), the cut-cell no-slip solve
// (GhostCellWalls) against its own rows, and Poiseuille flow in a tube through the Navier–Stokes step, aligned with the
// grid and at 30° to it, against π G R⁴ / 8μ.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <memory>
#include <vector>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/GhostCellWalls.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/walls/WallGeometry.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic;

WallShape tube(Vec3 c, Vec3 axis, double R) { return {WallShape::Kind::Tube, c, axis, R, 0, "wall[0]"}; }
WallShape sphere(Vec3 c, double R) { return {WallShape::Kind::Sphere, c, {}, R, 0, "wall[0]"}; }
WallShape box(Vec3 c, Vec3 size, bool fluid_inside) {
  WallShape s{WallShape::Kind::Box, c, {}, 0, 0, "wall[0]"};
  s.size = size;
  s.fluid_inside = fluid_inside;
  return s;
}
WallShape constriction(Vec3 c, Vec3 axis, Vec3 size, Vec3 throat) {
  WallShape s{WallShape::Kind::Constriction, c, axis, 0, 0, "wall[0]"};
  s.size = size;
  s.throat = throat;
  return s;
}

struct TubeResult {
  double flow_rate, exact;
  long steps;
  std::size_t cuts;
};

// The steady flow under the body force G t (ρ = μ = 1) by stepping from rest with ν Δt = 2h², at most max_steps steps,
// steady when the flow rate changes by less than 1e-12 of itself in a step; the flow rate (1/period) ∫_fluid u·t dV.
TubeResult steady_flow_rate(const Grid& g, const std::shared_ptr<const WallGeometry>& w, Vec3 t, double period,
                            double G, long max_steps) {
  FluidParams prm;
  prm.rho = 1;
  prm.mu = 1;
  prm.body_force = G * t;
  prm.walls = w;
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  GhostCellWalls walls(g, *prm.walls);
  FluidState a = ns.initial_state(), b;
  const double h = g.h(), dt = 2 * h * h;
  const auto rate = [&](const FluidState& s) {
    double q = 0;
    for (int d = 0; d < 3; ++d) {
      const auto& u = s.u[d].values();
      for (std::size_t i = 0; i < u.size(); ++i)
        if (walls.fluid(d, i)) q += u[i] * t[d];
    }
    return q * h * h * h / period;
  };
  long steps = 0;
  double q = 0;
  while (steps < max_steps) {
    ++steps;
    ns.step(a, FaceField(g), dt, b);
    std::swap(a, b);
    const double qn = rate(a);
    const bool steady = std::abs(qn - q) <= 1e-12 * std::abs(qn);
    q = qn;
    if (steady) break;
  }
  return {q, 0.0, steps, walls.cut_count(0) + walls.cut_count(1) + walls.cut_count(2)};
}

// Steady Poiseuille flow in a tube of radius R = r_h h along t = (sx Lx, 0, sz Lz) normalized (sx = 0: along z), from
// rest; against π G R⁴ / 8μ.
TubeResult tube_flow(int r_h, int nx, int ny, int nz, int sx, long max_steps) {
  const double h = 1.0 / r_h, R = 1.0;
  const Grid g({nx, ny, nz}, {nx * h, ny * h, nz * h}, {P, P, P});
  const Vec3 along{sx * g.length(0), 0, g.length(2)};
  const double G = 4.0;
  TubeResult r = steady_flow_rate(
      g,
      std::make_shared<const WallGeometry>(
          std::vector<WallShape>{tube({0.5 * g.length(0), 0.5 * g.length(1), 0.5 * g.length(2)}, along, R)}, g),
      normalized(along), norm(along), G, max_steps);
  r.exact = std::numbers::pi * G / 8;
  return r;
}

}  // namespace

TEST(WallGeometry, TubeDistanceAndNormalAcrossThePeriodicBox) {
  const Grid g({16, 16, 8}, {4.0, 4.0, 2.0}, {P, P, P});
  const WallGeometry w({tube({2, 2, 1}, {0, 0, 3}, 1.5)}, g);
  EXPECT_DOUBLE_EQ(w.distance({2, 2, 0.3}), 1.5);
  EXPECT_NEAR(w.distance({2.5, 2, 1.9}), 1.0, 1e-15);
  EXPECT_NEAR(w.distance({3.0, 3.0, 0.0}), 1.5 - std::sqrt(2.0), 1e-15);
  const Vec3 n = w.normal({3.0, 2, 0.5});
  EXPECT_NEAR(n.x, -1.0, 1e-15);  // into the fluid, towards the axis
  EXPECT_NEAR(w.distance({0.01, 2, 0.5}), 1.5 - 1.99,
              1e-14);  // outside: inside the wall
  EXPECT_DOUBLE_EQ(w.shapes()[0].period, 2.0);
  // At 45 degrees the axis closes after (Lx, 0, Lz): a point across the x boundary is near the axis's image.
  const Grid c({16, 8, 16}, {4.0, 2.0, 4.0}, {P, P, P});
  const WallGeometry d({tube({2, 1, 2}, {1, 0, 1}, 0.8)}, c);
  EXPECT_NEAR(d.shapes()[0].period, 4 * std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(d.distance({0.0, 1, 0.0}), 0.8,
              1e-14);  // (0, 0) and (4, 4) lie on the images of the axis
  EXPECT_NEAR(d.distance({4.0 - 1e-9, 1, 0.0}), 0.8 - 1e-9 / std::sqrt(2.0),
              1e-12);  // (4, 0): the image after Lx
}

TEST(WallGeometry, SphereAcrossThePeriodicBoundaryAndTheUnionOfSolids) {
  const Grid g({8, 8, 8}, {2.0, 2.0, 2.0}, {P, P, P});
  const WallGeometry w({sphere({0.1, 1, 1}, 0.5), tube({1, 1, 1}, {0, 1, 0}, 0.9)}, g);
  EXPECT_NEAR(w.distance({1.9, 1, 1}), std::min(0.2 - 0.5, 0.9 - 0.9),
              1e-15);  // the sphere's image is nearer
  EXPECT_NEAR(w.distance({1.0, 0.5, 1.0}), std::sqrt(0.81 + 0.25) - 0.5,
              1e-15);  // on the tube's axis
  const Vec3 n = w.normal({1.9, 1, 1});
  EXPECT_NEAR(n.x, -1.0, 1e-15);  // out of the ball's image at x = 2.1
}

TEST(WallGeometry, RefusesShapesThatDoNotFitTheBox) {
  const Grid g({16, 16, 8}, {4.0, 4.0, 2.0}, {P, P, P});
  const auto message = [&](const WallShape& s) {
    try {
      WallGeometry({s}, g);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(tube({2, 2, 1}, {0.1234567, 0, 1}, 1)).find("wall[0].axis = [0.123457, 0, 1]: a tube must close"),
            std::string::npos);
  EXPECT_NE(message(tube({2, 2, 1}, {0, 0, 1}, 2)).find("wall[0].radius = 2: the tube meets its periodic image"),
            std::string::npos);
  EXPECT_NE(message(sphere({5, 2, 1}, 0.5)).find("wall[0].center = [5, 2, 1]: must lie in the box"), std::string::npos);
  EXPECT_NE(message(sphere({2, 2, 1}, 1.0)).find("the sphere meets its periodic image"), std::string::npos);
  const Grid walled({16, 16, 8}, {4.0, 4.0, 2.0}, {P, P, Boundary::Wall});
  EXPECT_THROW(WallGeometry({tube({2, 2, 1}, {0, 0, 1}, 1)}, walled), InputError);
  EXPECT_THROW(GhostCellWalls(walled, WallGeometry({tube({2, 2, 1}, {0, 0, 1}, 1)}, g)), InputError);
}

// A solid block, a rectangular duct (a fluid box spanning x) and a constriction: exact distances at faces, edges and
// corners, the throat's frame, the periodic image, invariance, and the displayed surface's area.
TEST(WallGeometry, BoxDuctAndConstriction) {
  const Grid g({16, 16, 16}, {4.0, 4.0, 4.0}, {P, P, P});
  const WallGeometry block({box({2, 2, 2}, {1, 2, 1}, false)}, g);
  EXPECT_NEAR(block.distance({2, 2, 2}), -0.5, 1e-15);
  EXPECT_NEAR(block.distance({3, 2, 2}), 0.5, 1e-15);
  EXPECT_NEAR(block.distance({3, 3.5, 3}), std::sqrt(0.75), 1e-15);  // nearest: the corner (2.5, 3, 2.5)
  EXPECT_NEAR(block.distance({0.1, 2, 2}), 1.4, 1e-15);               // the image at x = −2 is 2.1 − 0.5 away
  EXPECT_NEAR(block.normal({3, 2, 2}).x, 1.0, 1e-15);
  EXPECT_FALSE(block.invariant_along(0));

  const WallGeometry duct({box({2, 2, 2}, {4, 2, 3}, true)}, g);
  EXPECT_NEAR(duct.distance({0.3, 2, 2}), 1.0, 1e-15);
  EXPECT_NEAR(duct.distance({1, 3.5, 2}), -0.5, 1e-15);
  EXPECT_NEAR(duct.distance({1, 3.5, 3.75}), -std::sqrt(0.25 + 0.0625), 1e-15);
  EXPECT_NEAR(duct.normal({1, 2.9, 2}).y, -1.0, 1e-15);  // into the fluid
  EXPECT_TRUE(duct.invariant_along(0));
  EXPECT_FALSE(duct.invariant_along(1));

  // A 2 × 2 channel along x narrowed to 1 in y over a length 1 about x = 2.
  const WallGeometry c({constriction({2, 2, 2}, {1, 0, 0}, {4, 2, 2}, {1, 1, 2})}, g);
  EXPECT_NEAR(c.distance({0.2, 2, 2}), 1.0, 1e-15);   // the channel's walls
  EXPECT_NEAR(c.distance({2, 2, 2}), 0.5, 1e-15);     // the throat's
  EXPECT_NEAR(c.distance({2, 2.8, 2}), -0.3, 1e-15);  // in the frame, under the throat's face y = 2.5
  EXPECT_NEAR(c.distance({1.3, 2.8, 2}), 0.2, 1e-15); // before the frame's face x = 1.5
  EXPECT_NEAR(c.normal({1.3, 2.6, 2}).x, -1.0, 1e-15);
  EXPECT_FALSE(c.invariant_along(0));

  // The displayed walls: the duct's four faces over one period, 2 (2 + 3) 4 = 40, less the chamfers of its four edges
  // across at most one lattice cell, 4 · 4 (2 − √2) h.
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  std::vector<int> of;
  duct.triangulate(g.h(), v, t, of);
  double area = 0, off = 0;
  for (const auto& tri : t) area += 0.5 * norm(cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]]));
  for (const Vec3& x : v) off = std::max(off, std::abs(duct.distance(x)));
  EXPECT_LE(area, 40.0 + 1e-12);
  EXPECT_GE(area, 40.0 - 16 * (2 - std::sqrt(2.0)) * g.h());
  EXPECT_LE(off, 1e-12);  // the faces lie between lattice planes: every crossing is on them
  EXPECT_EQ(of.size(), t.size());

  const auto message = [&](const WallShape& s) {
    try {
      WallGeometry({s}, g);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(box({2, 2, 2}, {4, 4, 5}, true)).find("wall[0].size = [4, 4, 5]: the box spans the whole"),
            std::string::npos);
  EXPECT_NE(message(box({2, 2, 2}, {1, -1, 1}, false)).find("every edge must be positive"), std::string::npos);
  EXPECT_NE(message(constriction({2, 2, 2}, {1, 1, 0}, {4, 2, 2}, {1, 1, 2})).find("a coordinate axis"),
            std::string::npos);
  EXPECT_NE(message(constriction({2, 2, 2}, {1, 0, 0}, {4, 2, 2}, {1, 3, 2})).find("wider than the channel"),
            std::string::npos);
  EXPECT_NE(message(constriction({2, 2, 2}, {1, 0, 0}, {4, 2, 2}, {4, 1, 2})).find("the throat's length along x"),
            std::string::npos);
  EXPECT_NE(message(constriction({2, 2, 2}, {1, 0, 0}, {4, 2, 2}, {1, 2, 2})).find("must be narrower"),
            std::string::npos);
}

// Every row of the system the solve answers: the cut (Shortley–Weller) rows at the cut points, the periodic rows
// elsewhere in the fluid, and 0 in the wall.
// Walls not invariant along an axis (a tube with a sphere in it: the dense capacitance matrix) and a tube along y (its
// block-circulant matrix, one block per wavenumber along y).
void expect_rows_solved(const Grid& g, const WallGeometry& w) {
  GhostCellWalls walls(g, w);
  for (int d = 0; d < 3; ++d) {
    FftHelmholtzSolver fast(g, velocity_layout(d), FftPlanning::Estimate);
    Array3 b(g.n(0), g.n(1), g.n(2));
    for (std::size_t i = 0; i < b.size(); ++i) b.data()[i] = std::sin(0.37 * static_cast<double>(i)) + 0.5;
    Array3 x = b;
    const double alpha = 1.0, beta = -2e-3;
    walls.solve(d, x, alpha, beta, fast);
    ASSERT_GT(walls.cut_count(d), 100u);
    EXPECT_LE(walls.cut_residual(d, x, b), 1e-10) << d;
    double worst = 0;
    const double inv_h2 = 1.0 / (g.h() * g.h());
    const auto at = [&](int i, int j, int k) {
      const auto wrap = [](int q, int m) { return (q % m + m) % m; };
      return x(wrap(i, g.n(0)), wrap(j, g.n(1)), wrap(k, g.n(2)));
    };
    std::size_t f = 0, cut = 0;
    for (int k = 0; k < g.n(2); ++k)
      for (int j = 0; j < g.n(1); ++j)
        for (int i = 0; i < g.n(0); ++i, ++f) {
          const bool fluid = walls.fluid(d, f);
          const bool near = !walls.fluid(d, b.index((i + 1) % g.n(0), j, k)) ||
                            !walls.fluid(d, b.index((i + g.n(0) - 1) % g.n(0), j, k)) ||
                            !walls.fluid(d, b.index(i, (j + 1) % g.n(1), k)) ||
                            !walls.fluid(d, b.index(i, (j + g.n(1) - 1) % g.n(1), k)) ||
                            !walls.fluid(d, b.index(i, j, (k + 1) % g.n(2))) ||
                            !walls.fluid(d, b.index(i, j, (k + g.n(2) - 1) % g.n(2)));
          if (fluid && near) {
            ++cut;
            continue;
          }
          const double lap = (at(i - 1, j, k) + at(i + 1, j, k) + at(i, j - 1, k) + at(i, j + 1, k) + at(i, j, k - 1) +
                              at(i, j, k + 1) - 6 * at(i, j, k)) *
                             inv_h2;
          if (fluid)
            worst = std::max(worst, std::abs(alpha * x(i, j, k) + beta * lap - b(i, j, k)));
          else
            EXPECT_EQ(x(i, j, k), 0.0);  // the wall's velocity
        }
    EXPECT_EQ(cut, walls.cut_count(d));
    EXPECT_LE(worst, 1e-10) << d;
  }
}

TEST(GhostCellWalls, SolvesItsRowsToRoundOff) {
  const Grid g({20, 18, 6}, {1.0, 0.9, 0.3}, {P, P, P});
  expect_rows_solved(g, WallGeometry({tube({0.5, 0.45, 0.1}, {0, 0, 1}, 0.37), sphere({0.5, 0.45, 0.15}, 0.11)}, g));
  const Grid y({18, 10, 16}, {0.9, 0.5, 0.8}, {P, P, P});
  expect_rows_solved(y, WallGeometry({tube({0.45, 0.1, 0.4}, {0, -1, 0}, 0.33)}, y));
}

// Steady Poiseuille flow in a tube along z through the Navier–Stokes step: flow rate within 1 % of π G R⁴ / 8μ at D =
// 16h, and the error falls with h at an observed order of at least 1 over R = 8h, 16h, 32h.
TEST(TubeFlow, PoiseuilleFlowRateAndItsOrderUnderRefinement) {
  std::vector<double> errors;
  for (int r : {8, 16, 32}) {
    const int n = 2 * r + 4;
    const TubeResult res = tube_flow(r, n, n, 4, 0, 4000);
    const double error = res.flow_rate / res.exact - 1;
    std::printf(
        "tube along z, R = %dh: flow rate / (pi G R^4 / 8 mu) - 1 = "
        "%+.3e (%ld steps, %zu cut points)\n",
        r, error, res.steps, res.cuts);
    errors.push_back(std::abs(error));
  }
  EXPECT_LE(errors[0], 0.01);
  const double order = std::log(errors.front() / errors.back()) / std::log(4.0);
  std::printf("observed order over R = 8h .. 32h: %.2f\n", order);
  EXPECT_GE(order, 1.0);
}

// The same tube at 30° to z (axis along (Lx, 0, Lz), Lx/Lz = 15/26): D = 16h, within 1 %.
TEST(TubeFlow, AtThirtyDegreesToTheGrid) {
  const TubeResult res = tube_flow(8, 30, 20, 52, 1, 1000);  // steady to 1e-6: -2.744e-3 after 4000 steps
  const double error = res.flow_rate / res.exact - 1;
  std::printf(
      "tube at %.2f degrees, R = 8h: flow rate / (pi G R^4 / 8 mu) - 1 "
      "= %+.3e (%ld steps, %zu cut points)\n",
      std::atan2(30.0, 52.0) * 180 / std::numbers::pi, error, res.steps, res.cuts);
  EXPECT_LE(std::abs(error), 0.01);
}

namespace {

struct DragResult {
  double K;
  long steps;
  std::size_t cuts;
};

// Stokes flow through a simple cubic array of spheres: one sphere of volume fraction c in a periodic cube of n cells
// (side L = 1), driven by a body force g along x in the fluid. The drag on each sphere is F = g L³ (the fluid's and the
// mean pressure gradient's force balance), and Zick & Homsy's K = F / (6πμ a U) with U the superficial velocity
// (1/L³) ∫_fluid u_x dV. The steady state by steps cycling through ν Δt = 4^k h², k = 0 … 5, which damp every mode
// (Crank–Nicolson with ν Δt λ/2 within a factor 2 of 1 divides it by 3 or more), until U changes by less than 1e-10
// of itself over a cycle, or for 100 cycles (U then changes by about 1e-7 of itself per cycle, some 1e-6 in all). ρ = 1e-3 μ L / U: a Reynolds number about 1e-5.
DragResult sphere_array(int n, double c) {
  const double h = 1.0 / n;
  const Grid g({n, n, n}, {1.0, 1.0, 1.0}, {P, P, P});
  const double a = std::cbrt(3 * c / (4 * std::numbers::pi));
  FluidParams prm;
  prm.rho = 1e-3;
  prm.mu = 1;
  prm.body_force = {1, 0, 0};
  prm.walls = std::make_shared<const WallGeometry>(std::vector<WallShape>{sphere({0.5, 0.5, 0.5}, a)}, g);
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  GhostCellWalls walls(g, *prm.walls);
  FluidState s = ns.initial_state(), next;
  const auto superficial = [&](const FluidState& f) {
    double sum = 0;
    const auto& u = f.u[0].values();
    for (std::size_t i = 0; i < u.size(); ++i)
      if (walls.fluid(0, i)) sum += u[i];
    return sum * h * h * h;
  };
  double U = 0;
  long steps = 0;
  for (int cycle = 0; cycle < 100; ++cycle) {
    for (int k = 0; k < 6; ++k, ++steps) {
      ns.step(s, FaceField(g), std::pow(4.0, k) * h * h * prm.rho / prm.mu, next);
      std::swap(s, next);
    }
    const double Un = superficial(s);
    const bool steady = std::abs(Un - U) <= 1e-10 * std::abs(Un);
    U = Un;
    if (steady) break;
  }
  return {1.0 / (6 * std::numbers::pi * prm.mu * a * U), steps,
          walls.cut_count(0) + walls.cut_count(1) + walls.cut_count(2)};
}

}  // namespace

// Zick & Homsy (1982, J. Fluid Mech. 115:13, Table 2) for the simple cubic array, within 2 % at three volume fractions.
TEST(SphereArray, StokesDragAgainstZickAndHomsy) {
  const struct {
    double c, K;
  } table[] = {{0.027, 2.008}, {0.064, 2.810}, {0.125, 4.292}};
  for (const auto& row : table) {
    const DragResult r = sphere_array(32, row.c);
    std::printf("simple cubic array, c = %.3f on 32^3: K = %.4f against %.3f (%+.2f %%; %ld steps, %zu cut points)\n",
                row.c, r.K, row.K, 100 * (r.K / row.K - 1), r.steps, r.cuts);
    EXPECT_NEAR(r.K / row.K, 1.0, 0.02) << row.c;
  }
}

// Steady flow in a square duct of side 2a (a box with the fluid inside, spanning z) along z, its walls off the lattice
// planes: the flow rate against the exact series (Cornish 1928, Proc. R. Soc. A 120:691)
//   Q = (4 a⁴ G / 3μ) (1 − (192/π⁵) Σ_{n odd} tanh(nπ/2)/n⁵),
// within 1 % at a side of 16h, and the error's observed order over a = 8h, 16h.
TEST(DuctFlow, SquareDuctFlowRateAgainstTheSeries) {
  double sum = 0;
  for (int n = 1; n < 200; n += 2) sum += std::tanh(n * std::numbers::pi / 2) / std::pow(n, 5);
  const double G = 4.0, exact = 4.0 * G / 3.0 * (1 - 192 / std::pow(std::numbers::pi, 5) * sum);
  std::vector<double> errors;
  for (int r : {8, 16}) {
    const double h = 1.0 / r;
    const int n = 2 * r + 4;
    const Grid g({n, n, 4}, {n * h, n * h, 4 * h}, {P, P, P});
    const Vec3 c{0.5 * g.length(0) + 0.3 * h, 0.5 * g.length(1) - 0.2 * h, 0.5 * g.length(2)};
    const TubeResult res = steady_flow_rate(
        g, std::make_shared<const WallGeometry>(std::vector<WallShape>{box(c, {2, 2, g.length(2)}, true)}, g),
        {0, 0, 1}, g.length(2), G, 4000);
    const double error = res.flow_rate / exact - 1;
    std::printf("square duct, side %dh: flow rate / series - 1 = %+.3e (%ld steps, %zu cut points)\n", 2 * r, error,
                res.steps, res.cuts);
    errors.push_back(std::abs(error));
  }
  EXPECT_LE(errors[0], 0.01);
  const double order = std::log(errors[0] / errors[1]) / std::log(2.0);
  std::printf("observed order over a = 8h, 16h: %.2f\n", order);
  EXPECT_GE(order, 1.0);
}

// A flow rate held through a constriction (walls that vary along the flow, so the controller's response is projected):
// every step ends at the mean velocity asked for, the flux through every cross-section is the same (the step is
// divergence-free), the fluid speeds up in the throat, and the controller's force settles.
TEST(DuctFlow, FlowRateIsHeldThroughAConstriction) {
  const Grid g({32, 16, 16}, {4.0, 2.0, 2.0}, {P, P, P});
  FluidParams prm;
  prm.rho = 1;
  prm.mu = 1;
  prm.flow_axis = 0;
  prm.flow_mean_velocity = 0.25;
  prm.walls = std::make_shared<const WallGeometry>(
      std::vector<WallShape>{constriction({2.03, 1.02, 0.98}, {1, 0, 0}, {4, 1.5, 1.5}, {1, 0.75, 1.5})}, g);
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  GhostCellWalls walls(g, *prm.walls);
  EXPECT_TRUE(walls.open_along(0));
  EXPECT_FALSE(walls.open_along(1));
  FluidState a = ns.initial_state(), b;
  const double h = g.h(), dt = 2 * h * h;
  double force = 0;
  for (int step = 0; step < 60; ++step) {
    ns.step(a, FaceField(g), dt, b);
    std::swap(a, b);
    const Array3& u = a.u[0];
    double mean = 0;
    for (std::size_t i = 0; i < u.size(); ++i)
      if (walls.fluid(0, i)) mean += u.data()[i];
    mean /= static_cast<double>(u.size());
    ASSERT_NEAR(mean, 0.25, 1e-12) << step;
    double lo = 1e300, hi = -1e300;
    for (int i = 0; i < g.n(0); ++i) {
      double q = 0;
      for (int k = 0; k < g.n(2); ++k)
        for (int j = 0; j < g.n(1); ++j) q += u(i, j, k);
      lo = std::min(lo, q);
      hi = std::max(hi, q);
    }
    ASSERT_LE(hi - lo, 1e-10 * hi) << step;
    force = a.flow_force;
  }
  const double throat = a.u[0](16, 8, 8), channel = a.u[0](1, 8, 8);
  std::printf("constriction: centre velocity %.4f in the throat, %.4f in the channel; force %.4f\n", throat, channel,
              force);
  EXPECT_GT(throat, 1.5 * channel);
  EXPECT_GT(force, 0.0);
  ns.step(a, FaceField(g), dt, b);
  EXPECT_NEAR(b.flow_force, force, 1e-3 * force);  // steady
}
