// Unit tests of the MAC Navier–Stokes solver (paper eqs. 9–13): parameter validation, purity of the step, the
// prepared step shared by several forces, discrete operator identities, the fast-transform eigen-systems, boundary
// values and the variable-step AB2.
#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/verify/Convergence.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double pi = std::numbers::pi;

void randomize(Array3& a, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  for (double& v : a.values()) v = U(rng);
}

// Random state with homogeneous-wall-compatible values.
FluidState random_state(const NavierStokesSolver& ns, std::mt19937& rng) {
  FluidState s = ns.initial_state();
  for (int d = 0; d < 3; ++d) randomize(s.u[d], rng);
  randomize(s.p, rng);
  ns.apply_wall_values(s.u);
  return s;
}

bool same(const Array3& a, const Array3& b) { return a.values() == b.values(); }
bool same(const FaceField& a, const FaceField& b) { return same(a[0], b[0]) && same(a[1], b[1]) && same(a[2], b[2]); }

double inner(const Array3& a, const Array3& b) {
  double s = 0;
  for (std::size_t n = 0; n < a.size(); ++n) s += a[n] * b[n];
  return s;
}

}  // namespace

TEST(FluidParams, RejectsNonPositiveDensityViscosityAndTimeStep) {
  const Grid g({4, 4, 4}, {1, 1, 1}, {P, P, W});
  FluidParams p;
  p.rho = -1;
  try {
    NavierStokesSolver ns(g, p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "fluid.rho = -1: must be > 0");
  }
  p.rho = 1;
  p.mu = 0;
  EXPECT_THROW(NavierStokesSolver(g, p), InputError);
  p.mu = 1;
  p.wall_lower[2] = {0, 0, 0.1};  // normal wall velocities differ: net flux through the box
  EXPECT_THROW(NavierStokesSolver(g, p), InputError);
  p.wall_lower[2] = {};
  NavierStokesSolver ns(g, p, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  try {
    ns.step(a, FaceField(g), 0.0, b);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "fluid.dt = 0: must be > 0");
  }
  EXPECT_THROW(ns.step(a, FaceField(g), 0.1, a), std::invalid_argument);
}

TEST(NavierStokesSolver, StepIsPureAndReusesTheOutputStorage) {
  const Grid g({8, 6, 4}, {1, 0.75, 0.5}, {W, P, W});
  FluidParams prm;
  prm.mu = 0.1;
  prm.wall_upper[0] = {0, 0.3, -0.2};
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  std::mt19937 rng(3);
  const FluidState in = random_state(ns, rng);
  FaceField force(g);
  for (int d = 0; d < 3; ++d) randomize(force[d], rng);
  const FluidState copy = in;
  FluidState out1, out2;
  ns.step(in, force, 0.01, out1);
  EXPECT_TRUE(same(in.u, copy.u) && same(in.p, copy.p) && same(in.adv, copy.adv));
  const double* pu = out1.u[1].data();
  const double* pp = out1.p.data();
  ns.step(in, force, 0.01, out1);  // again into the same storage
  EXPECT_EQ(out1.u[1].data(), pu);
  EXPECT_EQ(out1.p.data(), pp);
  ns.step(in, force, 0.01, out2);
  EXPECT_TRUE(same(out1.u, out2.u) && same(out1.p, out2.p) && same(out1.adv, out2.adv));
  EXPECT_EQ(out1.step, in.step + 1);
  EXPECT_DOUBLE_EQ(out1.time, in.time + 0.01);
}

// prepare() then step() under several forces on the one prepared step, each bitwise the plain step(in, force, dt):
// on the first step (forward Euler) and on later ones (Adams–Bashforth with r = 0.7 and r = 0.7/1.3), with moving
// walls, periodic axes and a body force, with the lagged pressure of (9) and the extrapolated one (from the third
// step on). Two code paths (the plain step builds the right-hand side in one pass): the prepared step
// is only read and shares nothing with the plain steps taken in between. It refers to the state it was made from:
// a change of that state's step counter or time is detected, and that state cannot be the output.
TEST(NavierStokesSolver, PreparedStepUnderSeveralForcesEqualsThePlainStepBitwise) {
  for (const auto pressure : {PressurePredictor::Lagged, PressurePredictor::Extrapolated}) {
    for (const auto bc : {std::array<Boundary, 3>{W, P, W}, {P, W, P}}) {
      const Grid g({8, 6, 5}, {1, 0.75, 0.625}, bc);
      FluidParams prm;
      prm.pressure = pressure;
      prm.mu = 0.1;
      prm.body_force = {0.5, -1, 0.25};
      for (int a = 0; a < 3; ++a)
        if (bc[a] == W) {
          prm.wall_lower[a] = {0.1, -0.2, 0.3};
          prm.wall_upper[a] = {-0.3, 0.4, 0.2};
          prm.wall_lower[a][a] = prm.wall_upper[a][a] = 0;
        }
      NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
      std::mt19937 rng(11);
      std::array<FaceField, 3> forces;
      for (auto& f : forces) {
        f = FaceField(g);
        for (int d = 0; d < 3; ++d) randomize(f[d], rng);
      }
      const FluidState first = random_state(ns, rng);
      FluidState later, latest;
      ns.step(first, forces[0], 0.01, later);
      ASSERT_EQ(later.step, 1);
      ASSERT_GT(later.dt_prev, 0.0);
      ns.step(later, forces[1], 0.013, latest);
      ASSERT_GT(latest.dt_prev2, 0.0);
      const FluidState other = random_state(ns, rng);
      for (const FluidState* in : std::array<const FluidState*, 3>{&first, &later, &latest}) {
        const double dt = 0.007;
        PreparedStep prepared;
        EXPECT_FALSE(prepared.prepared_for(*in, dt));
        ns.prepare(*in, dt, prepared);
        EXPECT_TRUE(prepared.prepared_for(*in, dt));
        EXPECT_FALSE(prepared.prepared_for(*in, 0.5 * dt));
        EXPECT_FALSE(prepared.prepared_for(in == &first ? later : first, dt));
        EXPECT_FALSE(prepared.prepared_for(FluidState(*in), dt));  // (another object)
        FluidState out, plain, scratch;
        std::vector<double> u_first;
        for (const auto& f : forces) {
          ns.step(prepared, f, out);
          ns.step(other, f, 0.02, scratch);
          ns.step(*in, f, dt, plain);
          EXPECT_TRUE(same(out.u, plain.u) && same(out.p, plain.p) && same(out.adv, plain.adv));
          EXPECT_TRUE(same(out.p_prev, in->p));
          EXPECT_EQ(out.step, plain.step);
          EXPECT_EQ(out.time, plain.time);
          EXPECT_EQ(out.dt_prev, plain.dt_prev);
          EXPECT_EQ(out.dt_prev2, in->dt_prev);
          if (u_first.empty())
            u_first = out.u[0].values();
          else
            EXPECT_NE(out.u[0].values(), u_first);  // the forces do drive the flow
        }
      }
      FluidState out;
      EXPECT_THROW(ns.step(PreparedStep{}, forces[0], out), std::invalid_argument);
      FluidState source = later;
      PreparedStep prepared;
      ns.prepare(source, 0.007, prepared);
      EXPECT_THROW(ns.step(prepared, forces[0], source), std::invalid_argument);
      ++source.step;
      EXPECT_THROW(ns.step(prepared, forces[0], out), std::logic_error);
      --source.step;
      source.time += 0.007;
      EXPECT_THROW(ns.step(prepared, forces[0], out), std::logic_error);
      source.time = later.time;
      ns.step(prepared, forces[1], out);
      FluidState plain;
      ns.step(later, forces[1], 0.007, plain);
      EXPECT_TRUE(same(out.u, plain.u) && same(out.p, plain.p) && same(out.adv, plain.adv));
    }
  }
}

// The trials of an implicit step write into one output state and copy the prepared (u·∇_h u)^n into it once
// (FluidState::adv_of). An output state passed from one prepared step to another, to a re-prepared one, or through a
// plain step, must still end up with the advection of the step it was last written by.
TEST(NavierStokesSolver, AnOutputStateSharedByPreparedStepsHoldsTheAdvectionOfEach) {
  const Grid g({8, 6, 5}, {1, 0.75, 0.625}, {P, W, W});
  NavierStokesSolver ns(g, FluidParams{}, FftPlanning::Estimate);
  std::mt19937 rng(23);
  FaceField force(g);
  for (int d = 0; d < 3; ++d) randomize(force[d], rng);
  const FluidState s1 = random_state(ns, rng), s2 = random_state(ns, rng);
  const double dt = 0.01;
  FluidState plain1, plain2;
  ns.step(s1, force, dt, plain1);
  ns.step(s2, force, dt, plain2);
  ASSERT_FALSE(same(plain1.adv, plain2.adv));
  const auto matches = [&](const FluidState& out, const FluidState& plain) {
    return same(out.u, plain.u) && same(out.p, plain.p) && same(out.adv, plain.adv);
  };
  PreparedStep p1, p2;
  ns.prepare(s1, dt, p1);
  ns.prepare(s2, dt, p2);
  FluidState out;
  for (int round = 0; round < 2; ++round) {
    ns.step(p1, force, out);
    EXPECT_TRUE(matches(out, plain1));
    ns.step(p1, force, out);  // (the copy skipped)
    EXPECT_TRUE(matches(out, plain1));
    ns.step(p2, force, out);
    EXPECT_TRUE(matches(out, plain2));
  }
  ns.prepare(s2, dt, p1);  // the same object prepared again, from the other state
  ns.step(p1, force, out);
  EXPECT_TRUE(matches(out, plain2));
  ns.prepare(s1, dt, p1);
  ns.step(p1, force, out);
  EXPECT_TRUE(matches(out, plain1));
  ns.step(s2, force, dt, out);  // a plain step in between
  EXPECT_TRUE(matches(out, plain2));
  ns.step(p1, force, out);
  EXPECT_TRUE(matches(out, plain1));
  FluidState copy = out;  // a copy holds the advection it was copied with
  ns.step(p1, force, copy);
  EXPECT_TRUE(matches(copy, plain1));
}

TEST(NavierStokesSolver, ForceOnWallFacesIsIgnored) {
  const Grid g({6, 6, 6}, {1, 1, 1}, {W, W, P});
  NavierStokesSolver ns(g, FluidParams{}, FftPlanning::Estimate);
  std::mt19937 rng(5);
  const FluidState in = random_state(ns, rng);
  FaceField force(g);
  for (int d = 0; d < 3; ++d) randomize(force[d], rng);
  FaceField garbage = force;
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j) {
      garbage[0](0, j, k) = 1e6;
      garbage[0](6, j, k) = -1e6;
      garbage[1](j, 0, k) = 1e6;
    }
  FluidState a, b;
  ns.step(in, force, 0.01, a);
  ns.step(in, garbage, 0.01, b);
  EXPECT_TRUE(same(a.u, b.u) && same(a.p, b.p));
}

TEST(NavierStokesSolver, ResultsDoNotDependOnTheThreadCount) {
  const Grid g({64, 32, 32}, {2, 1, 1}, {P, W, W});  // large enough to be threaded
  ASSERT_TRUE(MacStencilGrid(g).threaded());
  FluidParams prm;
  prm.mu = 0.05;
  prm.wall_upper[1] = {0.5, 0, 0.1};
  std::array<FluidState, 2> result;
  const int threads = omp_get_max_threads();
  for (int t = 0; t < 2; ++t) {
    omp_set_num_threads(t == 0 ? 1 : 2);
    NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
    std::mt19937 rng(9);
    FluidState a = random_state(ns, rng), b;
    for (int n = 0; n < 3; ++n) {
      ns.step(a, FaceField(g), 0.01, b);
      std::swap(a, b);
    }
    result[t] = a;
  }
  omp_set_num_threads(threads);
  // Stencils are pointwise; FFTW's threaded plans may reorder round-off only.
  EXPECT_LE(velocity_difference(g, result[0].u, result[1].u).max, 1e-13);
  EXPECT_LE(pressure_difference(result[0].p, result[1].p).max, 1e-12);
}

TEST(MacOperators, DivergenceIsMinusTheAdjointOfTheGradient) {
  for (auto bc : {std::array<Boundary, 3>{P, P, P}, {W, P, W}, {W, W, W}}) {
    const Grid g({6, 8, 10}, {0.6, 0.8, 1.0}, bc);
    const MacStencilGrid geom(g);
    std::mt19937 rng(1);
    FaceField u(g);
    for (int d = 0; d < 3; ++d) randomize(u[d], rng);
    NavierStokesSolver(g, FluidParams{}, FftPlanning::Estimate).apply_wall_values(u);  // zero normal velocity
    Array3 phi(6, 8, 10);
    randomize(phi, rng);
    Array3 div;
    divergence(g, u, div);
    double ug = 0;
    for (int d = 0; d < 3; ++d)
      for (int k = geom.first(d, 2); k < geom.n[2]; ++k)
        for (int j = geom.first(d, 1); j < geom.n[1]; ++j)
          for (int i = geom.first(d, 0); i < geom.n[0]; ++i)
            ug += u[d](i, j, k) * mac::gradient_face(phi, geom, d, {i, j, k});
    EXPECT_NEAR(inner(phi, div), -ug, 1e-12 * std::abs(ug));
  }
}

// The row kernels of the step's fast path (MacStencil_K.hpp) against the generic ones, on every face where they
// apply, for every boundary combination and both accessors: the same operations in the same order, so bitwise.
template <int D>
int row_kernel_mismatches(const MacStencilGrid& g, const FaceField& u, const Array3& p) {
  int bad = 0;
  const IndexBox box = interior_face_box(g, D);
  for (int k = box.begin[2]; k < box.end[2]; ++k)
    for (int j = box.begin[1]; j < box.end[1]; ++j) {
      const mac::WrappedRows w0(u[0], g, j, k), w1(u[1], g, j, k), w2(u[2], g, j, k), wd(u[D], g, j, k),
          wp(p, g, j, k);
      for (int i = box.begin[0]; i < box.end[0]; ++i) {
        const mac::Index q{i, j, k};
        const auto wrap = [&](int m) { return g.periodic[0] ? mac::wrap(m, g.n[0]) : m; };
        const mac::XIndex x{wrap(i - 1), i, wrap(i + 1)};
        const mac::FaceStencil st = mac::gather(u[D], g, D, q);
        const double adv = mac::advection_face(u, g, D, q, st), grad = mac::gradient_face(p, g, D, q);
        const double lap = mac::laplacian(st, g);
        bad += mac::wall_source_face(g, D, q) != 0.0;
        const auto check = [&](const auto& r0, const auto& r1, const auto& r2, const auto& rd, const auto& rp) {
          const mac::FaceStencil sr = mac::gather_row(rd, x);
          bad += mac::advection_row<D>(sr, r0, r1, r2, x, g.inv_h) != adv;
          bad += mac::gradient_row<D>(rp, x, g.inv_h) != grad;
          bad += mac::laplacian(sr, g) != lap;
        };
        check(w0, w1, w2, wd, wp);
        if (!mac::row_wraps(g, j, k))
          check(mac::Strided(u[0], g, j, k), mac::Strided(u[1], g, j, k), mac::Strided(u[2], g, j, k),
                mac::Strided(u[D], g, j, k), mac::Strided(p, g, j, k));
      }
    }
  return bad;
}

TEST(MacOperators, RowKernelsEqualTheGenericOnesBitwise) {
  for (int combo = 0; combo < 8; ++combo) {
    std::array<Boundary, 3> bc{};
    for (int a = 0; a < 3; ++a) bc[a] = (combo >> a) & 1 ? W : P;
    const Grid g({7, 6, 5}, {0.7, 0.6, 0.5}, bc);
    FluidParams prm;
    for (int a = 0; a < 3; ++a) {
      prm.wall_lower[a] = {0.3, -0.2, 0.1};
      prm.wall_upper[a] = {-0.4, 0.5, 0.7};
      prm.wall_lower[a][a] = prm.wall_upper[a][a] = 0.25;
    }
    const MacStencilGrid geom(g, prm);
    std::mt19937 rng(static_cast<unsigned>(combo));
    FaceField u(g);
    for (int d = 0; d < 3; ++d) randomize(u[d], rng);
    Array3 p(7, 6, 5);
    randomize(p, rng);
    long faces = 0;
    for (int d = 0; d < 3; ++d) {
      const IndexBox b = interior_face_box(geom, d);
      faces += static_cast<long>(b.end[0] - b.begin[0]) * (b.end[1] - b.begin[1]) * (b.end[2] - b.begin[2]);
    }
    EXPECT_GT(faces, 0) << "combination " << combo;
    EXPECT_EQ(row_kernel_mismatches<0>(geom, u, p), 0) << "combination " << combo;
    EXPECT_EQ(row_kernel_mismatches<1>(geom, u, p), 0) << "combination " << combo;
    EXPECT_EQ(row_kernel_mismatches<2>(geom, u, p), 0) << "combination " << combo;
    int bad = 0;
    for (int k = 0; k < 5; ++k)
      for (int j = 0; j < 6; ++j) {
        const mac::WrappedRows r0(u[0], geom, j, k), r1(u[1], geom, j, k), r2(u[2], geom, j, k);
        for (int i = 0; i < 7; ++i) {
          const auto wrap = [&](int m) { return geom.periodic[0] ? mac::wrap(m, 7) : m; };
          const mac::XIndex x{wrap(i - 1), i, wrap(i + 1)};
          bad += mac::divergence_row(r0, r1, r2, x, geom.inv_h) != mac::divergence_cell(u, geom, {i, j, k});
        }
      }
    EXPECT_EQ(bad, 0) << "combination " << combo;
  }
}

TEST(MacOperators, HomogeneousLaplacianIsSymmetricOnEveryLayout) {
  const Grid g({6, 8, 10}, {0.6, 0.8, 1.0}, {W, P, W});
  std::mt19937 rng(2);
  for (int l = 0; l < 4; ++l) {
    const auto s = l == 3 ? g.cell_shape() : g.face_shape(l);
    Array3 x(s[0], s[1], s[2]), y(s[0], s[1], s[2]), lx, ly;
    randomize(x, rng);
    randomize(y, rng);
    if (l == 0)  // wall faces of u are not unknowns
      for (int k = 0; k < s[2]; ++k)
        for (int j = 0; j < s[1]; ++j) x(0, j, k) = x(6, j, k) = y(0, j, k) = y(6, j, k) = 0;
    if (l == 2)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) x(i, j, 0) = x(i, j, 10) = y(i, j, 0) = y(i, j, 10) = 0;
    apply_operator(g, static_cast<Layout>(l), x, 0, 1, lx);
    apply_operator(g, static_cast<Layout>(l), y, 0, 1, ly);
    EXPECT_NEAR(inner(x, ly), inner(lx, y), 1e-12 * std::abs(inner(lx, y))) << "layout " << l;
  }
}

// The eigen-systems of docs/theory/conventions.md: a product of the tabulated eigenvectors is reproduced by the solver.
TEST(FftHelmholtzSolver, ReproducesTheTabulatedEigenvectors) {
  const Grid g({8, 6, 10}, {0.8, 0.6, 1.0}, {W, P, W});
  const double h = g.h();
  const auto lam_wall = [&](int k, int n) { return -4 / (h * h) * std::pow(std::sin(pi * k / (2.0 * n)), 2); };
  const auto lam_per = [&](int k, int n) { return -4 / (h * h) * std::pow(std::sin(pi * k / n), 2); };
  const int kx = 3, ky = 2, kz = 5;
  for (int l = 0; l < 4; ++l) {
    const Layout layout = static_cast<Layout>(l);
    const auto s = l == 3 ? g.cell_shape() : g.face_shape(l);
    // x: wall axis (8 cells); y: periodic (6); z: wall axis (10 cells).
    const auto fx = [&](int i) {
      if (l == 0) return std::sin(pi * kx * i / 8.0);          // face-normal: DST-I
      if (l == 3) return std::cos(pi * kx * (i + 0.5) / 8.0);  // pressure: DCT-II
      return std::sin(pi * kx * (i + 0.5) / 8.0);              // cell-centred velocity: DST-II
    };
    const auto fz = [&](int k) {
      if (l == 2) return std::sin(pi * kz * k / 10.0);
      if (l == 3) return std::cos(pi * kz * (k + 0.5) / 10.0);
      return std::sin(pi * kz * (k + 0.5) / 10.0);
    };
    const double lambda = lam_wall(kx, 8) + lam_per(ky, 6) + lam_wall(kz, 10);
    Array3 x(s[0], s[1], s[2]);
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) x(i, j, k) = fx(i) * std::cos(2 * pi * ky * j / 6.0) * fz(k);
    const double alpha = 1.0, beta = -0.3 * h * h;
    Array3 b = x;
    for (double& v : b.values()) v *= alpha + beta * lambda;
    Array3 residual;
    apply_operator(g, layout, x, alpha, beta, residual);  // the eigenvalue is that of the 7-point operator
    for (std::size_t n = 0; n < b.size(); ++n) {
      if (residual[n] != 0) {
        EXPECT_NEAR(residual[n], b[n], 1e-12) << "layout " << l;
      }
    }
    FftHelmholtzSolver(g, layout, FftPlanning::Estimate).solve(b, alpha, beta);
    for (std::size_t n = 0; n < b.size(); ++n) EXPECT_NEAR(b[n], x[n], 1e-13) << "layout " << l;
  }
}

TEST(FftHelmholtzSolver, HelmholtzSolutionMatchesTheManufacturedOne) {
  std::mt19937 rng(4);
  for (auto bc : {std::array<Boundary, 3>{P, W, P}, {W, W, W}}) {
    const Grid g({6, 10, 8}, {0.6, 1.0, 0.8}, bc);
    for (int l = 0; l < 3; ++l) {
      const auto s = g.face_shape(l);
      Array3 x(s[0], s[1], s[2]);
      randomize(x, rng);
      const MacStencilGrid geom(g);
      // zero the wall faces (not unknowns)
      Array3 xu(s[0], s[1], s[2]);
      for_each_face(geom, l, [&](int i, int j, int k) { xu(i, j, k) = x(i, j, k); });
      Array3 b;
      apply_operator(g, static_cast<Layout>(l), xu, 1.0, -0.05, b);
      FftHelmholtzSolver(g, static_cast<Layout>(l), FftPlanning::Estimate).solve(b, 1.0, -0.05);
      for (std::size_t n = 0; n < b.size(); ++n) EXPECT_NEAR(b[n], xu[n], 1e-12);
    }
  }
}

TEST(NavierStokesSolver, UniformBodyForceAcceleratesAPeriodicBoxUniformly) {
  const Grid g({4, 6, 8}, {0.5, 0.75, 1.0}, {P, P, P});
  FluidParams prm;
  prm.rho = 2;
  prm.body_force = {1, -2, 0.5};
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  for (int n = 0; n < 5; ++n) {
    ns.step(a, FaceField(g), 0.1, b);
    std::swap(a, b);
  }
  const auto e = velocity_error(g, a.u, [&](const Vec3&) { return prm.body_force * (0.5 / prm.rho); });
  EXPECT_LE(e.max, 1e-14);
}

TEST(NavierStokesSolver, UniformFlowThroughWallsWithEqualNormalVelocityIsSteady) {
  const Grid g({6, 6, 8}, {0.75, 0.75, 1.0}, {P, W, W});
  FluidParams prm;
  prm.wall_lower[2] = prm.wall_upper[2] = {0.2, 0, 0.3};
  prm.wall_lower[1] = prm.wall_upper[1] = {0.2, 0, 0.3};
  NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  sample_velocity(
      g,
      [](const Vec3&) {
        return Vec3{0.2, 0, 0.3};
      },
      a.u);
  for (int n = 0; n < 4; ++n) {
    ns.step(a, FaceField(g), 0.05, b);
    std::swap(a, b);
  }
  EXPECT_LE(velocity_error(g, a.u, [](const Vec3&) { return Vec3{0.2, 0, 0.3}; }).max, 1e-14);
  EXPECT_LE(pressure_difference(a.p, Array3(6, 6, 8)).max, 1e-12);
}

// (10) with a variable step: AB2 weights (1 + r/2, −r/2). Steps alternating Δt and Δt/2 stay second order
// (the constant weights 3/2, −1/2 would make the scheme first order). The reference is the same grid with a
// tiny constant step, so the spatial error cancels.
// The extrapolated pressure p^{n−1/2} + w (p^{n−1/2} − p^{n−3/2}) is exact for a pressure linear in time, at the
// t^{n+1/2} of any step after any two steps (each pressure half its step behind the velocity); w = 1 for a constant
// step and 0 before two steps are taken.
TEST(NavierStokesSolver, ExtrapolatedPressureIsExactForAPressureLinearInTime) {
  const auto p = [](double t) { return 2.0 - 3.0 * t; };
  for (const std::array<double, 3> steps :
       {std::array<double, 3>{0.1, 0.1, 0.1}, {0.05, 0.1, 0.3}, {0.2, 0.07, 0.01}}) {
    const auto [dt2, dt1, dt] = steps;  // the steps that produced p^{n−3/2} and p^{n−1/2}, and the next one
    const double tn = 1.0, p1 = p(tn - 0.5 * dt1), p0 = p(tn - dt1 - 0.5 * dt2);
    EXPECT_NEAR(p1 + extrapolation_weight(dt, dt1, dt2) * (p1 - p0), p(tn + 0.5 * dt), 1e-14);
  }
  EXPECT_EQ(extrapolation_weight(0.1, 0.1, 0.1), 1.0);
  EXPECT_EQ(extrapolation_weight(0.1, 0.1, 0.0), 0.0);
}

// A step from a state whose pressures differ takes p̃ when extrapolating: the result differs from the lagged one,
// and equals the lagged step from the state whose p^{n−1/2} is p̃ (its (13) continues from p̃ as well).
TEST(NavierStokesSolver, ExtrapolatedStepIsTheLaggedStepFromTheExtrapolatedPressure) {
  const Grid g({8, 6, 5}, {1, 0.75, 0.625}, {W, P, W});
  FluidParams lag, ext;
  lag.mu = ext.mu = 0.1;
  ext.pressure = PressurePredictor::Extrapolated;
  NavierStokesSolver nl(g, lag, FftPlanning::Estimate), ne(g, ext, FftPlanning::Estimate);
  std::mt19937 rng(5);
  FluidState in = random_state(nl, rng);
  randomize(in.p_prev, rng);
  in.step = 2;
  in.dt_prev = 0.01;
  in.dt_prev2 = 0.02;
  FaceField force(g);
  for (int d = 0; d < 3; ++d) randomize(force[d], rng);
  FluidState shifted = in, a, b, c;
  const double dt = 0.015, w = extrapolation_weight(dt, in.dt_prev, in.dt_prev2);
  for (std::size_t i = 0; i < in.p.size(); ++i) shifted.p[i] = in.p[i] + w * (in.p[i] - in.p_prev[i]);
  ne.step(in, force, dt, a);
  nl.step(shifted, force, dt, b);
  nl.step(in, force, dt, c);
  EXPECT_TRUE(same(a.u, b.u) && same(a.p, b.p));
  EXPECT_FALSE(same(a.u, c.u));
  EXPECT_TRUE(same(a.p_prev, in.p));
}

TEST(NavierStokesSolver, VariableStepAdamsBashforthStaysSecondOrder) {
  const TaylorGreen tg{2 * pi, 1.0, 0.01};
  const Grid g({24, 24, 2}, {1, 1, 2.0 / 24}, {P, P, P});
  for (const auto pressure : {PressurePredictor::Lagged, PressurePredictor::Extrapolated}) {
    FluidParams prm;
    prm.mu = tg.mu;
    prm.pressure = pressure;
    NavierStokesSolver ns(g, prm, FftPlanning::Estimate);
    const double T = 0.3;
    const auto run = [&](const std::vector<double>& pattern, int repeats) {
      FluidState a = ns.initial_state(), b;
      sample_velocity(
          g, [&](const Vec3& x) { return tg.velocity(x, 0); }, a.u);
      sample_pressure(
          g, [&](const Vec3& x) { return tg.pressure(x, -0.5 * pattern[0]); }, a.p);
      for (int r = 0; r < repeats; ++r)
        for (double dt : pattern) {
          ns.step(a, FaceField(g), dt, b);
          std::swap(a, b);
        }
      return a;
    };
    const FluidState ref = run({T / 1200}, 1200);
    std::vector<double> errors;
    for (int m : {10, 20, 40}) {
      const double dt = T / (1.5 * m);
      errors.push_back(velocity_difference(g, run({dt, 0.5 * dt}, m).u, ref.u).max);
    }
    EXPECT_GE(verify::min_observed_order(errors), 1.9);
  }
}

// Plane Couette flow u_x = U_lower + k (z − z_lower): the discrete wall stress is μ k on both walls, exactly; a
// uniform χ in the wall cells scales it by 1 + χ; a parabolic profile u_x = a z (Lz − z) gives ±μ a (Lz − h/2), the
// viscous flux the scheme applies at the wall (first order in h as a derivative; in a discrete steady state it is the
// flux that balances the momentum exactly).
TEST(FluidDiagnostics, WallShearStressOfCouetteAndParabolicFlows) {
  const Grid grid({8, 6, 10}, {0.8, 0.6, 1.0}, {P, P, W}, {0.0, 0.0, -0.3});
  const double mu = 0.7, k = 1.9, lower = -0.4, upper = lower + k * 1.0;
  FaceField u(grid);
  sample_velocity(grid, [&](const Vec3& x) { return Vec3{lower + k * (x.z + 0.3), 0.0, 0.0}; }, u);
  EXPECT_NEAR(wall_shear_stress(grid, u, nullptr, mu, false, lower), mu * k, 1e-13);
  EXPECT_NEAR(wall_shear_stress(grid, u, nullptr, mu, true, upper), mu * k, 1e-13);
  Array3 chi(8, 6, 10, 0.0);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 8; ++i) chi(i, j, 0) = 4.0;
  EXPECT_NEAR(wall_shear_stress(grid, u, &chi, mu, false, lower), 5.0 * mu * k, 1e-12);
  EXPECT_NEAR(wall_shear_stress(grid, u, &chi, mu, true, upper), mu * k, 1e-13);
  const double a = 3.0;
  sample_velocity(grid, [&](const Vec3& x) { return Vec3{a * (x.z + 0.3) * (0.7 - x.z), 0.0, 0.0}; }, u);
  const double h = grid.h();
  EXPECT_NEAR(wall_shear_stress(grid, u, nullptr, mu, false, 0.0), mu * a * (1.0 - h / 2), 1e-12);
  EXPECT_NEAR(wall_shear_stress(grid, u, nullptr, mu, true, 0.0), -mu * a * (1.0 - h / 2), 1e-12);
  EXPECT_THROW(wall_shear_stress(Grid({8, 6, 10}, {0.8, 0.6, 1.0}, {P, P, P}), u, nullptr, mu, false, 0.0),
               std::invalid_argument);
}
