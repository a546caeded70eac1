// The membrane integrators of §2.4 on a coupled problem with an exact solution (ToyOperator.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "PetscEnvironment.hpp"
#include "ToyOperator.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/timestep/AdaptiveStepper.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"
#include "immerse/verify/Convergence.hpp"

using namespace immerse;
using immerse::testing::ToyOperator;

namespace {

constexpr double K = 40.0, A = 0.5, RHO = 1.0, X0 = 0.1, T = 1.0;

ToyOperator make_toy(double k = K) { return ToyOperator({1.0 + X0, 2.0, 3.0}, {1.0, 2.0, 3.0}, k, A, RHO); }

// Errors of x and v against the exact damped oscillator, in the max norm over the trajectory on [0, T]
// (an error at one instant can pass through zero and fake a convergence order).
std::pair<double, double> run(const std::string& scheme, int steps, SolverSettings s = {}) {
  auto op = make_toy();
  auto integ = make_integrator(scheme, s);
  const double dt = T / steps;
  double ex = 0, ev = 0;
  for (int i = 0; i < steps; ++i) {
    const auto st = integ->step(op, dt);
    EXPECT_TRUE(st.converged) << st.failure;
    const auto [x, v] = op.exact(X0, op.time());
    ex = std::max(ex, std::abs(op.positions()[0] - 1.0 - x));
    ev = std::max(ev, std::abs(op.velocity()[0] - v));
  }
  return {ex, ev};
}

double order(const std::string& scheme, bool of_velocity, SolverSettings s = {}, int coarsest = 40) {
  std::vector<double> e;
  for (int steps : {coarsest, 2 * coarsest, 4 * coarsest}) {
    const auto [ex, ev] = run(scheme, steps, s);
    e.push_back(of_velocity ? ev : ex);
  }
  return verify::min_observed_order(e);
}

// `f` throws an InputError whose message contains `text` (the key or option it names).
template <class F>
void expect_input_error(F&& f, const std::string& text) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected an error naming " << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Integrators, TrapezoidalJfnkIsSecondOrderForPositionAndVelocity) {
  const double px = order("jfnk", false), pv = order("jfnk", true);
  std::cout << "jfnk observed orders: X " << px << ", u " << pv << "\n";
  EXPECT_GE(px, 1.9);
  EXPECT_GE(pv, 1.9);
}

TEST(Integrators, QuasiNewtonVariantsAreSecondOrder) {
  for (const char* scheme : {"bfgs", "lbfgs"}) {
    const double px = order(scheme, false), pv = order(scheme, true);
    std::cout << scheme << " observed orders: X " << px << ", u " << pv << "\n";
    EXPECT_GE(px, 1.9) << scheme;
    EXPECT_GE(pv, 1.9) << scheme;
  }
}

TEST(Integrators, AndersonAccelerationIsSecondOrder) {
  // The same trapezoidal update (31), solved by Anderson acceleration instead of Newton: the same orders.
  const double px = order("anderson", false), pv = order("anderson", true);
  std::cout << "anderson observed orders: X " << px << ", u " << pv << "\n";
  EXPECT_GE(px, 1.9);
  EXPECT_GE(pv, 1.9);
}

TEST(Integrators, MidpointRK2IsSecondOrderAndEulerFirst) {
  const double p2 = order("rk2", false), p1 = order("euler", false);
  std::cout << "rk2 order " << p2 << ", euler order " << p1 << "\n";
  EXPECT_GE(p2, 1.9);
  EXPECT_GE(p1, 0.9);
  EXPECT_LE(p1, 1.2);
}

TEST(Integrators, BackwardEulerThetaIsFirstOrder) {
  SolverSettings s;
  s.theta = 1.0;
  const double p = order("jfnk", false, s, 320);
  std::cout << "theta = 1 order " << p << "\n";
  EXPECT_GE(p, 0.9);
  EXPECT_LE(p, 1.2);
}

TEST(Integrators, BackwardEulerRemovesTheRingingOfStiffModes) {
  // K = 1e4, dt = 0.05: the stiff mode's trapezoidal amplification factor is close to -1 (it rings, barely damped),
  // the L-stable theta = 1 damps it in a few steps.
  SolverSettings trap, be;
  be.theta = 1.0;
  auto a = make_toy(1e4), b = make_toy(1e4);
  auto ia = make_integrator("jfnk", trap), ib = make_integrator("jfnk", be);
  int sign_changes = 0;
  double prev = X0;
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(ia->step(a, 0.05).converged);
    ASSERT_TRUE(ib->step(b, 0.05).converged);
    const double x = a.positions()[0] - 1.0;
    sign_changes += (x * prev < 0);
    prev = x;
  }
  std::cout << "after 20 steps: trapezoidal |x| = " << std::abs(prev) << " (" << sign_changes
            << " sign changes), backward Euler |x| = " << std::abs(b.positions()[0] - 1.0) << "\n";
  EXPECT_GE(sign_changes, 15);
  EXPECT_GT(std::abs(prev), 0.1 * X0);
  EXPECT_LT(std::abs(b.positions()[0] - 1.0), 1e-3 * X0);
}

TEST(Integrators, QuasiNewtonAndAndersonAndJfnkReachTheSameStep) {
  SolverSettings s;
  s.newton_rtol = 1e-12;
  auto a = make_toy(), b = make_toy(), c = make_toy(), d = make_toy();
  auto jfnk = make_integrator("jfnk", s), bfgs = make_integrator("bfgs", s), lbfgs = make_integrator("lbfgs", s);
  auto anderson = make_integrator("anderson", s);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(jfnk->step(a, 0.05).converged);
    EXPECT_TRUE(bfgs->step(b, 0.05).converged);
    EXPECT_TRUE(lbfgs->step(c, 0.05).converged);
    EXPECT_TRUE(anderson->step(d, 0.05).converged);
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a.positions()[i], b.positions()[i], 1e-10);
    EXPECT_NEAR(a.positions()[i], c.positions()[i], 1e-10);
    EXPECT_NEAR(a.positions()[i], d.positions()[i], 1e-10);
  }
}

TEST(Integrators, StiffSpringBreaksEulerButNotJfnk) {
  // K = 1e4: Euler's stability limit is dt ~ 2 sqrt(rho/K)-ish; take dt = 0.05, far beyond.
  auto e = make_toy(1e4), j = make_toy(1e4);
  auto euler = make_integrator("euler", {}), jfnk = make_integrator("jfnk", {});
  for (int i = 0; i < 40; ++i) {
    euler->step(e, 0.05);
    const auto st = jfnk->step(j, 0.05);
    ASSERT_TRUE(st.converged) << st.failure;
    EXPECT_LE(st.newton_its, 4);
  }
  EXPECT_GT(std::abs(e.positions()[0] - 1.0), 1e3);   // explicit: blown up
  EXPECT_LT(std::abs(j.positions()[0] - 1.0), X0);     // implicit: bounded, decaying
}

TEST(Integrators, JfnkCountsIterationsAndFluidSolves) {
  auto op = make_toy();
  auto jfnk = make_integrator("jfnk", {});
  jfnk->step(op, 0.05);
  const auto st = jfnk->step(op, 0.05);
  ASSERT_TRUE(st.converged);
  EXPECT_GE(st.newton_its, 1);
  EXPECT_GE(st.gmres_its, st.newton_its);
  // One g(X) per Newton iterate plus one per GMRES product (eq. 36).
  EXPECT_EQ(st.fluid_solves, static_cast<std::size_t>(1 + st.newton_its + st.gmres_its));
  EXPECT_LT(st.residual, 1e-8);
}

TEST(Integrators, BadNamesAndSettingsAreRejected) {
  EXPECT_THROW(make_integrator("leapfrog", {}), InputError);
  SolverSettings s;
  s.gmres_rtol = 0;
  EXPECT_THROW(make_integrator("jfnk", s), InputError);
  SolverSettings a;
  a.anderson_beta = 0;
  expect_input_error([&] { make_integrator("anderson", a); }, "solver.anderson_beta");
  a.anderson_beta = 0.85;
  a.anderson_memory = 0;
  EXPECT_THROW(make_integrator("anderson", a), InputError);
  SolverSettings p;
  p.petsc_options = "-snes_no_such_option 3";
  auto op = make_toy();
  auto jfnk = make_integrator("jfnk", p);
  expect_input_error([&] { jfnk->step(op, 0.05); }, "-snes_no_such_option");
}

// solver.petsc_options wins over PETSC_OPTIONS, and both over the anderson_* settings they repeat; options of JFNK's
// KSP or matrix-free Jacobian are reported as unused by Anderson (it has neither), after its first solve.
TEST(Integrators, AndersonTakesItsPetscOptionsOverItsSettings) {
  // Three steps with beta from the setting, from solver.petsc_options or from PETSC_OPTIONS (`environment`): the
  // positions reached (bitwise).
  auto positions = [](double beta, const std::string& options, const char* environment = nullptr) {
    if (environment) setenv("PETSC_OPTIONS", environment, 1);
    SolverSettings s;
    s.anderson_beta = beta;
    s.petsc_options = options;
    auto op = make_toy();
    auto anderson = make_integrator("anderson", s);
    unsetenv("PETSC_OPTIONS");  // read when the integrator is made
    for (int i = 0; i < 3; ++i) {
      const auto st = anderson->step(op, 0.05);
      EXPECT_TRUE(st.converged) << st.failure;
    }
    return std::vector<double>(op.positions().begin(), op.positions().end());
  };
  const auto reference = positions(0.85, "");
  EXPECT_NE(positions(0.3, ""), reference);  // beta changes the iterates, so the accepted positions
  EXPECT_EQ(positions(0.3, "-snes_anderson_beta 0.85"), reference);
  EXPECT_EQ(positions(0.3, "", "-snes_anderson_beta 0.85"), reference);
  EXPECT_EQ(positions(0.3, "-snes_anderson_beta 0.85", "-snes_anderson_beta 0.5"), reference);
  SolverSettings s;
  s.petsc_options = "-ksp_gmres_restart 50";
  auto op = make_toy();
  auto anderson = make_integrator("anderson", s);
  expect_input_error([&] { anderson->step(op, 0.05); },
                     "solver.petsc_options: option -ksp_gmres_restart was used by none of the 'anderson' solver's "
                     "PETSc objects");
  EXPECT_TRUE(anderson->step(op, 0.05).converged);  // reported once: the solver goes on if asked to
}

// The differencing of (36) is PETSc's MatMFFD: its -mat_mffd_* options are taken from solver.petsc_options (they
// were once reported as unknown), and change the products.
TEST(Integrators, MatrixFreeDifferencingOptionsAreTaken) {
  SolverSettings coarse;
  coarse.petsc_options = "-mat_mffd_type ds -mat_mffd_err 1e-4";
  auto a = make_toy(), b = make_toy();
  auto ja = make_integrator("jfnk", {}), jb = make_integrator("jfnk", coarse);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(ja->step(a, 0.05).converged);
    const auto st = jb->step(b, 0.05);
    ASSERT_TRUE(st.converged) << st.failure;
  }
  bool differ = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    differ = differ || a.positions()[i] != b.positions()[i];
    EXPECT_NEAR(a.positions()[i], b.positions()[i], 1e-7);
  }
  EXPECT_TRUE(differ) << "-mat_mffd_err had no effect on the products";
}

namespace {
// Fails every fluid step longer than a threshold, as a node leaving the domain would.
class Fragile final : public CoupledOperator {
 public:
  explicit Fragile(ToyOperator& inner, double max_dt) : in_(inner), max_dt_(max_dt) {}
  std::size_t size() const override { return in_.size(); }
  std::span<const double> positions() const override { return in_.positions(); }
  std::span<const double> node_velocity() const override { return in_.node_velocity(); }
  double length_scale() const override { return 1.0; }
  void trial_velocity(std::span<const double> Xf, double theta, std::span<const double> Xi, double dt,
                      std::span<double> U) override {
    if (dt > max_dt_) throw SimulationError("node 0 is outside the fluid domain");
    in_.trial_velocity(Xf, theta, Xi, dt, U);
  }
  void committed_velocity(std::span<const double> Xi, std::span<double> U) override {
    in_.committed_velocity(Xi, U);
  }
  bool trial_matches(std::span<const double> X) const override { return in_.trial_matches(X); }
  void commit(std::span<const double> X, double dt) override { in_.commit(X, dt); }
  std::size_t fluid_solves() const override { return in_.fluid_solves(); }

 private:
  ToyOperator& in_;
  double max_dt_;
};
}  // namespace

namespace {
// A coupled problem on which unpreconditioned GMRES cannot make progress: U(X) = u0 - (2 alpha / dt) C (X - X^n)
// with C the cyclic shift, so that g(X) = (I + alpha C)(X - X^n) - dt u0 and J = I + alpha C. J is normal with
// eigenvalues 1 + alpha e^{2 pi i k / n} on a circle around the origin for alpha > 1: a polynomial with p(0) = 1 and
// degree below n cannot be small on all of them (maximum principle), so GMRES's residual stays near its start until
// its Krylov space is the whole space, n products. For alpha < 1 the circle leaves the origin out and GMRES
// converges geometrically.
class CyclicShift final : public CoupledOperator {
 public:
  CyclicShift(std::size_t n, double alpha) : X_(n), u0_(n), trial_(n), alpha_(alpha) {
    for (std::size_t i = 0; i < n; ++i) {
      X_[i] = 0.01 * static_cast<double>(i);
      u0_[i] = std::cos(0.7 * static_cast<double>(i * i));
    }
  }
  std::size_t size() const override { return X_.size(); }
  std::span<const double> positions() const override { return X_; }
  std::span<const double> node_velocity() const override { return u0_; }
  double length_scale() const override { return 1.0; }
  void trial_velocity(std::span<const double> Xf, double, std::span<const double>, double dt,
                      std::span<double> U) override {
    ++solves_;
    const std::size_t n = X_.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + n - 1) % n;
      U[i] = u0_[i] - 2 * alpha_ / dt * (Xf[j] - X_[j]);
    }
    trial_.assign(Xf.begin(), Xf.end());
  }
  void committed_velocity(std::span<const double>, std::span<double> U) override {
    std::copy(u0_.begin(), u0_.end(), U.begin());
  }
  bool trial_matches(std::span<const double> X) const override { return std::ranges::equal(X, trial_); }
  void commit(std::span<const double> X, double) override { X_.assign(X.begin(), X.end()); }
  std::size_t fluid_solves() const override { return solves_; }

 private:
  std::vector<double> X_, u0_, trial_;
  double alpha_;
  std::size_t solves_ = 0;
};
}  // namespace

// A Newton system GMRES cannot solve is given up after the stall window (its residual did not halve in 30
// iterations), not after the 200-iteration limit: the step fails at once with a message that says why, and the
// adaptive step can halve it. A system it can solve is untouched by the test.
TEST(Integrators, JfnkGivesUpOnAStalledGmresEarly) {
  CyclicShift stiff(300, 2.0);
  auto jfnk = make_integrator("jfnk", {});
  const auto st = jfnk->step(stiff, 0.1);
  EXPECT_FALSE(st.converged);
  EXPECT_NE(st.failure.find("GMRES stalled"), std::string::npos) << st.failure;
  EXPECT_LE(st.fluid_solves, 35u);  // the first residual and 31 products at most (the limit would take 201)

  CyclicShift mild(300, 0.5);
  const auto ok = make_integrator("jfnk", {})->step(mild, 0.1);
  ASSERT_TRUE(ok.converged) << ok.failure;
  EXPECT_LT(ok.gmres_its, 30);
  const auto X = mild.positions();
  for (std::size_t i = 0; i < X.size(); ++i) {  // (I + alpha C)(X - X^n) = dt u0
    const std::size_t j = (i + X.size() - 1) % X.size();
    const double Xn_i = 0.01 * static_cast<double>(i), Xn_j = 0.01 * static_cast<double>(j);
    EXPECT_NEAR((X[i] - Xn_i) + 0.5 * (X[j] - Xn_j), 0.1 * std::cos(0.7 * static_cast<double>(i * i)), 1e-7);
  }
}

TEST(AdaptiveStepper, HalvesOnFailureAndGrowsBack) {
  auto toy = make_toy();
  Fragile op(toy, 0.03);
  auto jfnk = make_integrator("jfnk", {});
  AdaptiveStepper stepper(0.1, 1e-3, 2);
  std::vector<std::string> logs;
  auto log = [&](const std::string& s) { logs.push_back(s); };
  const auto first = stepper.advance(*jfnk, op, 1.0, log);
  EXPECT_DOUBLE_EQ(first.dt, 0.025);  // 0.1 -> 0.05 -> 0.025
  EXPECT_EQ(first.rejected, 2);
  ASSERT_EQ(logs.size(), 2u);
  EXPECT_NE(logs[0].find("outside the fluid domain"), std::string::npos) << logs[0];
  EXPECT_NE(logs[0].find("retrying with dt = 0.05"), std::string::npos) << logs[0];
  EXPECT_NEAR(toy.time(), 0.025, 1e-15);  // only the accepted step was committed
  stepper.advance(*jfnk, op, 1.0, log);   // second success: grows to 0.05
  EXPECT_DOUBLE_EQ(stepper.dt(), 0.05);
}

TEST(AdaptiveStepper, StopsBelowTheFloor) {
  auto toy = make_toy();
  Fragile op(toy, 1e-6);
  auto jfnk = make_integrator("jfnk", {});
  AdaptiveStepper stepper(0.1, 1e-3);
  EXPECT_THROW(stepper.advance(*jfnk, op, 1.0, [](const std::string&) {}), SimulationError);
  EXPECT_EQ(toy.time(), 0.0);
}
