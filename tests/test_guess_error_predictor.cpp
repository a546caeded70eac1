// The implicit step's initial guess: GuessErrorPredictor on sequences with known recurrences, its history rules, and
// its effect on JFNK (fewer fluid solves for the same steps).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numeric>
#include <random>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "PetscEnvironment.hpp"
#include "ToyOperator.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/timestep/GuessErrorPredictor.hpp"
#include "immerse/verify/OscillatingMembrane.hpp"

using namespace immerse;

namespace {

std::vector<double> random_vector(std::size_t n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<double> v(n);
  for (auto& x : v) x = N(gen);
  return v;
}

// e^k = r1^k v1 + r2^k v2: a soft mode decaying slowly and a stiff one ringing.
std::vector<double> two_modes(int k, double r1, double r2) {
  const auto v1 = random_vector(60, 1), v2 = random_vector(60, 2);
  std::vector<double> e(60);
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = std::pow(r1, k) * v1[i] + std::pow(r2, k) * v2[i];
  return e;
}

double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0, n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d += (a[i] - b[i]) * (a[i] - b[i]), n += b[i] * b[i];
  return std::sqrt(d / n);
}

// Positions X^n = -100 and their extrapolation X = 0: errors of size 1 are far above round-off and far
// below the displacement, so that only the recurrence decides. The prediction is then X itself.
std::vector<double> prediction(const GuessErrorPredictor& r, double dt, std::size_t n,
                               std::span<const std::size_t> offsets = {}) {
  std::vector<double> x(n, 0.0);
  r.predict(dt, std::vector<double>(n, -100.0), x, offsets);
  return x;
}

int terms(const GuessErrorPredictor& r, double dt, std::size_t n, std::span<const std::size_t> offsets = {}) {
  return r.terms(dt, std::vector<double>(n, -100.0), std::vector<double>(n, 0.0), offsets);
}

// e^k = sum_j r_j^k v_j over the modes r (random v_j of length n).
std::vector<double> modes(int k, const std::vector<double>& r, std::size_t n, unsigned seed) {
  std::vector<double> e(n, 0.0);
  for (std::size_t j = 0; j < r.size(); ++j) {
    const auto v = random_vector(n, seed + static_cast<unsigned>(j));
    for (std::size_t i = 0; i < n; ++i) e[i] += std::pow(r[j], k) * v[i];
  }
  return e;
}

}  // namespace

TEST(GuessErrorPredictor, PredictsARingingAndADecayingModeExactly) {
  GuessErrorPredictor r;
  for (int k = 0; k < 3; ++k) r.record(0.1, two_modes(k, 0.9, -0.95));
  EXPECT_EQ(terms(r, 0.1, 60), 2);
  EXPECT_LT(relative_difference(prediction(r, 0.1, 60), two_modes(3, 0.9, -0.95)), 1e-12);
  // A fourth error: the fit (three terms are singular for two modes: two) now on the last two errors, still exact.
  r.record(0.1, two_modes(3, 0.9, -0.95));
  EXPECT_LT(relative_difference(prediction(r, 0.1, 60), two_modes(4, 0.9, -0.95)), 1e-12);
}

TEST(GuessErrorPredictor, UsesOneTermForASingleModeAndNoneForUnrelatedErrors) {
  GuessErrorPredictor one;
  for (int k = 1; k <= 2; ++k) one.record(0.1, two_modes(k, -0.95, 0.0));  // (0^k = 0 for k >= 1: one mode)
  EXPECT_EQ(terms(one, 0.1, 60), 1);
  EXPECT_LT(relative_difference(prediction(one, 0.1, 60), two_modes(3, -0.95, 0.0)), 1e-12);
  one.record(0.1, two_modes(3, -0.95, 0.0));  // three errors of one mode: the two-term fit is singular
  EXPECT_EQ(terms(one, 0.1, 60), 1);
  EXPECT_LT(relative_difference(prediction(one, 0.1, 60), two_modes(4, -0.95, 0.0)), 1e-12);

  GuessErrorPredictor none;
  for (unsigned k = 0; k < 3; ++k) none.record(0.1, random_vector(60, 10 + k));
  EXPECT_EQ(terms(none, 0.1, 60), 0);
  for (double x : prediction(none, 0.1, 60)) EXPECT_EQ(x, 0.0);
}

TEST(GuessErrorPredictor, FitsUpToFiveTermsToTheLastTwoErrors) {
  const std::vector<double> r{0.95, 0.6, 0.1, -0.7, -0.97};
  GuessErrorPredictor rec;
  for (int k = 0; k < 7; ++k) rec.record(0.1, modes(k, r, 200, 20));
  EXPECT_EQ(terms(rec, 0.1, 200), 5);
  EXPECT_LT(relative_difference(prediction(rec, 0.1, 200), modes(7, r, 200, 20)), 1e-8);
}

// Two membranes with three modes each: one recurrence for all would need six terms; one per block is exact.
TEST(GuessErrorPredictor, FitsEachBlockItsOwnRecurrence) {
  const std::vector<double> ra{0.9, 0.3, -0.95}, rb{0.7, -0.2, -0.8};
  auto both = [&](int k) {
    auto e = modes(k, ra, 150, 30);
    const auto b = modes(k, rb, 90, 40);
    e.insert(e.end(), b.begin(), b.end());
    return e;
  };
  const std::vector<std::size_t> offsets{0, 150, 240};
  GuessErrorPredictor rec;
  for (int k = 0; k < 7; ++k) rec.record(0.1, both(k));
  EXPECT_EQ(terms(rec, 0.1, 240, offsets), 3);
  EXPECT_LT(relative_difference(prediction(rec, 0.1, 240, offsets), both(7)), 1e-8);
  EXPECT_GT(relative_difference(prediction(rec, 0.1, 240), both(7)), 1e-4);
  std::vector<double> X(240), Xn(240);
  EXPECT_THROW(rec.predict(0.1, Xn, X, std::vector<std::size_t>{0, 150}), std::logic_error);
}

TEST(GuessErrorPredictor, PredictionDoesNotDependOnTheNumberOfThreads) {
  const std::vector<std::size_t> offsets{0, 300, 600, 900, 1200};
  GuessErrorPredictor rec;
  for (int k = 0; k < 8; ++k) rec.record(0.1, modes(k, {0.9, 0.5, -0.3, -0.9}, 1200, 50));
  ASSERT_EQ(terms(rec, 0.1, 1200, offsets), 4);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = prediction(rec, 0.1, 1200, offsets);
  omp_set_num_threads(2);
  const auto two = prediction(rec, 0.1, 1200, offsets);
  omp_set_num_threads(threads);
  EXPECT_EQ(one, two);
  EXPECT_LT(relative_difference(one, modes(8, {0.9, 0.5, -0.3, -0.9}, 1200, 50)), 1e-8);
}

// A block whose recurrence stopped holding, an empty block and a block without errors predict nothing; the others
// go on predicting.
TEST(GuessErrorPredictor, SkipsOnlyTheBlocksWhereNoRecurrenceHolds) {
  const std::vector<double> ra{0.9, -0.95}, rb{0.7, -0.8};
  const std::vector<std::size_t> offsets{0, 100, 100, 180, 240};  // blocks a, (empty), b, zero
  auto errors = [&](int k, bool b_breaks) {
    auto e = modes(k, ra, 100, 70);
    const auto b = b_breaks ? random_vector(80, 200 + static_cast<unsigned>(k)) : modes(k, rb, 80, 80);
    e.insert(e.end(), b.begin(), b.end());
    e.resize(240, 0.0);
    return e;
  };
  GuessErrorPredictor rec;
  for (int k = 0; k < 4; ++k) rec.record(0.1, errors(k, false));
  auto p = prediction(rec, 0.1, 240, offsets);
  EXPECT_LT(relative_difference(p, errors(4, false)), 1e-10);
  // Block b's next error is unrelated to its recurrence, and larger than the prediction: it is skipped from now on.
  auto e4 = errors(4, false);
  const auto broken = random_vector(80, 300);
  for (std::size_t i = 0; i < 80; ++i) e4[100 + i] = 10 * broken[i];
  rec.record(0.1, e4);
  p = prediction(rec, 0.1, 240, offsets);
  const auto next = errors(5, false);
  for (std::size_t i = 100; i < 240; ++i) EXPECT_EQ(p[i], 0.0);
  const std::vector<double> pa(p.begin(), p.begin() + 100), ea(next.begin(), next.begin() + 100);
  EXPECT_LT(relative_difference(pa, ea), 1e-10);
}

namespace {

double norm(std::span<const double> v) { return std::sqrt(std::inner_product(v.begin(), v.end(), v.begin(), 0.0)); }

std::vector<double> scaled(std::vector<double> v, double size) {
  const double s = size / norm(v);
  for (auto& x : v) x *= s;
  return v;
}

// modes(k, r, n, seed) scaled so that the first error (k = 0) has norm `size`.
std::vector<double> sized_modes(int k, const std::vector<double>& r, std::size_t n, unsigned seed, double size) {
  auto e = modes(k, r, n, seed);
  const double s = size / norm(modes(0, r, n, seed));
  for (auto& x : e) x *= s;
  return e;
}

// Node coordinates of a cell of radius 4 um about the centre of a 24 um box (m).
std::vector<double> cell_positions(std::size_t n) {
  auto X = random_vector(n, 5);
  for (auto& x : X) x = 1.2e-5 + 4e-6 * std::tanh(x);
  return X;
}

// The extrapolation X^n + d with d of size `displacement`.
std::vector<double> extrapolated(const std::vector<double>& Xn, double displacement) {
  auto X = scaled(random_vector(Xn.size(), 6), displacement);
  for (std::size_t i = 0; i < X.size(); ++i) X[i] += Xn[i];
  return X;
}

// X - X0: the correction predict() added.
std::vector<double> correction(const GuessErrorPredictor& r, const std::vector<double>& Xn,
                               const std::vector<double>& X0) {
  auto X = X0;
  r.predict(0.1, Xn, X);
  for (std::size_t i = 0; i < X.size(); ++i) X[i] -= X0[i];
  return X;
}

}  // namespace

// Errors at round-off, 1e-16 of the positions, say nothing of the step, even when they follow a recurrence exactly
// (the same recurrence 1e12 times larger is predicted exactly): nothing is predicted.
TEST(GuessErrorPredictor, PredictsNothingFromRoundOffSizedErrors) {
  const std::size_t n = 300;
  const auto Xn = cell_positions(n);
  const auto X0 = extrapolated(Xn, 1e-3 * norm(Xn));
  const double size = 1e-16 * norm(Xn);
  GuessErrorPredictor noise, ringing, resolved;
  for (int k = 0; k < 8; ++k) {
    auto e = random_vector(n, 400 + static_cast<unsigned>(k));  // relative round-off of each coordinate
    for (std::size_t i = 0; i < n; ++i) e[i] *= 1e-16 * Xn[i];
    noise.record(0.1, e);
    ringing.record(0.1, sized_modes(k, {0.9, -0.95}, n, 90, size));
    resolved.record(0.1, sized_modes(k, {0.9, -0.95}, n, 90, 1e12 * size));
  }
  EXPECT_EQ(noise.terms(0.1, Xn, X0), 0);
  EXPECT_EQ(ringing.terms(0.1, Xn, X0), 0);
  for (double x : correction(noise, Xn, X0)) EXPECT_EQ(x, 0.0);
  for (double x : correction(ringing, Xn, X0)) EXPECT_EQ(x, 0.0);
  EXPECT_EQ(resolved.terms(0.1, Xn, X0), 2);
  EXPECT_LT(relative_difference(correction(resolved, Xn, X0), sized_modes(8, {0.9, -0.95}, n, 90, 1e12 * size)), 1e-6);
}

// The history of a red cell at rest: errors about the Newton tolerance (1e-8 ||X||) where Newton iterated, round-off
// where it accepted an unpredicted start at once. Fitted on the round-off-sized error before it, the last error would
// get a coefficient of order 1e8 and the guess would move by ||X||. Round-off-sized errors are not used, nor are those
// before them: a fit resumes with the errors after the last such one.
TEST(GuessErrorPredictor, UsesOnlyTheErrorsAboveRoundOff) {
  const std::size_t n = 300;
  const auto Xn = cell_positions(n);
  const auto X0 = extrapolated(Xn, 1e-3 * norm(Xn));
  auto roundoff = [&](unsigned seed) {
    auto e = random_vector(n, seed);
    for (std::size_t i = 0; i < n; ++i) e[i] *= 1e-16 * Xn[i];
    return e;
  };
  GuessErrorPredictor at_rest;
  at_rest.record(0.1, scaled(random_vector(n, 501), 1e-8 * norm(Xn)));
  at_rest.record(0.1, scaled(random_vector(n, 502), 1.5e-8 * norm(Xn)));
  at_rest.record(0.1, roundoff(503));
  const auto r = roundoff(504);
  at_rest.record(0.1, r);
  auto last = scaled(r, 1e-8 * norm(Xn));  // a multiple of the round-off-sized error before it, and a little more
  const auto extra = scaled(random_vector(n, 505), 1e-10 * norm(Xn));
  for (std::size_t i = 0; i < n; ++i) last[i] += extra[i];
  at_rest.record(0.1, last);
  EXPECT_EQ(at_rest.terms(0.1, Xn, X0), 0);
  for (double x : correction(at_rest, Xn, X0)) EXPECT_EQ(x, 0.0);

  // Resolved errors of two modes, one round-off-sized error among them: the three after it give the exact
  // two-term fit.
  const double size = 1e-6 * norm(Xn);
  GuessErrorPredictor broken;
  for (int k = 0; k < 6; ++k) broken.record(0.1, k == 2 ? roundoff(510) : sized_modes(k, {0.9, -0.95}, n, 90, size));
  EXPECT_EQ(broken.terms(0.1, Xn, X0), 2);
  EXPECT_LT(relative_difference(correction(broken, Xn, X0), sized_modes(6, {0.9, -0.95}, n, 90, size)), 1e-8);
}

// Under the trapezoidal rule no mode grows (|r| <= 1): a prediction larger than twice the last errors, or than twice
// the step's displacement (e^{n+1} = d^{n+1} - d^n with ||d^{n+1}|| <= ||d^n||), is refused.
TEST(GuessErrorPredictor, RefusesAPredictionLargerThanTheErrorsOrTheDisplacement) {
  const std::size_t n = 300;
  const auto Xn = cell_positions(n);
  const double size = 1e-6 * norm(Xn);
  GuessErrorPredictor growing, decaying;
  for (int k = 0; k < 4; ++k) {
    growing.record(0.1, sized_modes(k, {3.0}, n, 95, size));  // an exact recurrence, but growing
    decaying.record(0.1, sized_modes(k, {0.9}, n, 95, size));
  }
  const auto far = extrapolated(Xn, 1e3 * size);
  EXPECT_EQ(growing.terms(0.1, Xn, far), 0);
  for (double x : correction(growing, Xn, far)) EXPECT_EQ(x, 0.0);

  const double p = size * std::pow(0.9, 4);  // the decaying mode's next error, predicted exactly
  EXPECT_EQ(decaying.terms(0.1, Xn, far), 1);
  EXPECT_NEAR(norm(correction(decaying, Xn, far)), p, 1e-8 * p);
  const auto near = extrapolated(Xn, 0.55 * p), nearer = extrapolated(Xn, 0.45 * p);
  EXPECT_EQ(decaying.terms(0.1, Xn, near), 1);
  EXPECT_NEAR(norm(correction(decaying, Xn, near)), p, 1e-8 * p);
  EXPECT_EQ(decaying.terms(0.1, Xn, nearer), 0);
  for (double x : correction(decaying, Xn, nearer)) EXPECT_EQ(x, 0.0);
}

// Whatever the history (recurrences of modes, growing ones included, with noise; errors of sizes from round-off up;
// steps of any size), a prediction stays within twice the larger of the last two errors and twice the displacement.
TEST(GuessErrorPredictor, NeverMovesTheGuessFurtherThanItsBounds) {
  const std::size_t n = 120;
  const auto Xn = cell_positions(n);
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> uniform(0, 1);
  auto between = [&](double a, double b) { return a + (b - a) * uniform(gen); };
  int predicted = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::vector<double> r{between(-1.5, 1.5), between(-1.5, 1.5), between(-1.5, 1.5)};
    const double size = std::pow(10.0, between(-9, -3)) * norm(Xn), noise = std::pow(10.0, between(-6, 0));
    GuessErrorPredictor rec;
    std::vector<double> last, before;
    for (int k = 0; k < 8; ++k) {
      const double scale = uniform(gen) < 0.1 ? std::pow(10.0, between(-17, -3)) * norm(Xn) : size;
      auto e = sized_modes(k, r, n, 100 + static_cast<unsigned>(trial), 1.0);
      const auto v = random_vector(n, 10000 + static_cast<unsigned>(trial * 8 + k));
      for (std::size_t i = 0; i < n; ++i) e[i] = scale * (e[i] + noise * v[i] / std::sqrt(double(n)));
      rec.record(0.1, e);
      before = std::exchange(last, e);
    }
    const double displacement = std::pow(10.0, between(-1, 2)) * size;
    const double c = norm(correction(rec, Xn, extrapolated(Xn, displacement)));
    predicted += c > 0;
    EXPECT_LE(c, 2 * std::max(norm(last), norm(before)) * (1 + 1e-10)) << "trial " << trial;
    EXPECT_LE(c, 2 * displacement * (1 + 1e-10)) << "trial " << trial;
  }
  std::cout << "predictions made from " << predicted << " of 400 histories\n";
  EXPECT_GT(predicted, 40);
}

TEST(GuessErrorPredictor, StopsPredictingWhenItsLastPredictionMissedByMoreThanTheError) {
  GuessErrorPredictor r;
  for (int k = 0; k < 3; ++k) r.record(0.1, two_modes(k, 0.9, -0.95));
  ASSERT_EQ(terms(r, 0.1, 60), 2);
  // The recurrence stops holding: e^3 unrelated to the prediction two_modes(3), and of the same size.
  const auto predicted = two_modes(3, 0.9, -0.95);
  auto e3 = random_vector(60, 7);
  const double scale = std::sqrt(std::inner_product(predicted.begin(), predicted.end(), predicted.begin(), 0.0) /
                                 std::inner_product(e3.begin(), e3.end(), e3.begin(), 0.0));
  for (auto& x : e3) x *= scale;
  r.record(0.1, e3);
  EXPECT_EQ(terms(r, 0.1, 60), 0);
  for (double x : prediction(r, 0.1, 60)) EXPECT_EQ(x, 0.0);
}

TEST(GuessErrorPredictor, ForgetsItsHistoryWhenTheStepChanges) {
  GuessErrorPredictor r;
  for (int k = 0; k < 3; ++k) r.record(0.1, two_modes(k, 0.9, -0.95));
  EXPECT_EQ(terms(r, 0.05, 60), 0);  // errors scale with dt: none predicted for another step
  for (double x : prediction(r, 0.05, 60)) EXPECT_EQ(x, 0.0);
  r.record(0.05, two_modes(0, 0.9, -0.95));
  EXPECT_EQ(r.errors().size(), 60u);
  EXPECT_EQ(terms(r, 0.05, 60), 0);
}

TEST(GuessErrorPredictor, RestoreOfItsErrorsIsBitwise) {
  GuessErrorPredictor r, s;
  const std::vector<double> modes_r{0.8, 0.4, -0.5, -0.97};
  auto noisy = [&](int k) {  // a recurrence plus noise: the fits are inexact and the miss rule is exercised
    auto e = modes(k, modes_r, 60, 60);
    const auto n = random_vector(60, 100 + static_cast<unsigned>(k));
    for (std::size_t i = 0; i < e.size(); ++i) e[i] += 0.05 * n[i];
    return e;
  };
  for (int k = 0; k < 11; ++k) r.record(0.1, noisy(k));  // more than the eight stored: the oldest were dropped
  s.restore(r.errors(), 60, r.dt());
  EXPECT_EQ(s.errors(), r.errors());
  EXPECT_EQ(r.errors().size(), 8 * 60u);
  for (int k = 11; k < 14; ++k) {  // and they go on alike
    ASSERT_GT(terms(r, 0.1, 60), 0);
    EXPECT_EQ(prediction(s, 0.1, 60), prediction(r, 0.1, 60));
    r.record(0.1, noisy(k));
    s.record(0.1, noisy(k));
  }
  EXPECT_THROW(s.restore(std::vector<double>(61, 1.0), 60, 0.1), InputError);
  EXPECT_THROW(s.restore(std::vector<double>(540, 1.0), 60, 0.1), InputError);  // more than eight errors
}

// The Gram matrices are kept from step to step (each new error's dot products computed once, the oldest error's
// dropped with it): predictions made every step, by blocks that change now and then, are bitwise those of a
// recurrence rebuilt from the same errors, whose matrices are computed afresh.
TEST(GuessErrorPredictor, KeptGramMatricesGiveThePredictionsOfFreshOnes) {
  const std::vector<std::size_t> two{0, 90, 150}, three{0, 40, 90, 150};
  GuessErrorPredictor kept;
  int compared = 0;
  for (int k = 0; k < 16; ++k) {
    const auto& offsets = (k / 5) % 2 == 0 ? two : three;
    if (k > 0) {
      GuessErrorPredictor fresh;
      fresh.restore(kept.errors(), 150, kept.dt());
      const auto p = prediction(kept, 0.1, 150, offsets);
      EXPECT_EQ(p, prediction(fresh, 0.1, 150, offsets)) << "step " << k;
      compared += std::ranges::any_of(p, [](double x) { return x != 0; });
    }
    auto e = modes(k, {0.9, 0.6, -0.4, -0.9}, 150, 70);
    const auto noise = random_vector(150, 200 + static_cast<unsigned>(k));
    for (std::size_t i = 0; i < e.size(); ++i) e[i] += 1e-3 * noise[i];
    kept.record(0.1, e);
  }
  EXPECT_GE(compared, 10);  // most steps predict something
}

// The integrators keep the errors of extrapolated guesses over equal steps only: none after the first step (its
// guess is X^n + dt U^n), none across a change of step, none for an explicit scheme; at most eight.
TEST(GuessErrorPredictor, IntegratorsKeepTheErrorsOfEqualExtrapolatedStepsOnly) {
  auto stored = [](const MembraneIntegrator& m) { return m.guess_errors().errors().size() / 3; };
  immerse::testing::ToyOperator op({1.1, 2.0, 3.0}, {1.0, 2.0, 3.0}, 1e4, 0.5, 1.0);
  auto jfnk = make_integrator("jfnk", {});
  for (std::size_t expected : {0, 1, 2, 3, 4, 5, 6, 7, 8, 8}) {
    ASSERT_TRUE(jfnk->step(op, 0.05).converged);
    EXPECT_EQ(stored(*jfnk), expected);
  }
  ASSERT_TRUE(jfnk->step(op, 0.025).converged);
  EXPECT_EQ(stored(*jfnk), 0u);
  ASSERT_TRUE(jfnk->step(op, 0.025).converged);
  EXPECT_EQ(stored(*jfnk), 1u);

  immerse::testing::ToyOperator op2({1.1, 2.0, 3.0}, {1.0, 2.0, 3.0}, 40, 0.5, 1.0);
  auto rk2 = make_integrator("rk2", {});
  for (int i = 0; i < 4; ++i) rk2->step(op2, 0.01);
  EXPECT_EQ(stored(*rk2), 0u);
}

// §4.1's membrane, steps of dt = dx: the same positions (to the Newton tolerance) for fewer fluid solves.
TEST(GuessErrorPredictor, CutsTheFluidSolvesOfJfnkStepsWithoutChangingThem) {
  std::vector<std::vector<double>> X;
  std::vector<std::size_t> solves;
  for (auto guess : {SolverSettings::InitialGuess::Extrapolation, SolverSettings::InitialGuess::Recurrence}) {
    SolverSettings s;
    s.initial_guess = guess;
    verify::OscillatingMembrane exp(16, 2, 0.01);
    auto jfnk = make_integrator("jfnk", s);
    exp.run_to(*jfnk, 12.0 / 16, 1.0 / 16);
    solves.push_back(exp.op().fluid_solves());
    X.emplace_back(exp.op().positions().begin(), exp.op().positions().end());
  }
  std::cout << "12 JFNK steps: " << solves[0] << " fluid solves from the extrapolation, " << solves[1]
            << " with the recurrence; positions differ by " << relative_difference(X[1], X[0]) << " (relative)\n";
  EXPECT_LT(relative_difference(X[1], X[0]), 1e-7);
  EXPECT_LT(solves[1], solves[0]);
}

namespace {

// One red cell of scenarios/suspension_shear_quick.toml (642 nodes) at rest in the centre of the box: walls still,
// fluid at rest, energy-consistent forces.
constexpr const char* kCellAtRest = R"(
[scenario]
kind = "custom"
[domain]
Lx = 2.4e-5
Ly = 2.4e-5
Lz = 2.4e-5
[grid]
nx = 32
ny = 32
nz = 32
[boundary]
x = "periodic"
y = "periodic"
z = "wall"
[fluid]
rho = 1000.0
mu = 1.2e-3
initial = "rest"
[time]
dt = 1e-4
end = 1.0
[[membrane]]
shape = "rbc"
R0 = 3.91e-6
law = "skalak"
C11 = 1e-5
C21 = 1e-4
area_modulus = 1e-3
kappa_B = 2e-19
bending_reference = "rest"
viscosity_ratio = 5.0
volume_correction = "normal_shift"
mesh.family = "icosahedral"
mesh.level = 2
force = "energy"
)";

Simulation cell_at_rest(const std::string& initial_guess) {
  const std::vector<std::string> sets{"solver.initial_guess=" + initial_guess};
  return Simulation(apply_scenario(run_schema().parse_string(kCellAtRest, "cell at rest", sets)));
}

}  // namespace

// The cell at rest, with the history of errors such a run records (above): about the Newton tolerance where Newton
// iterated, round-off where it accepted an unpredicted start at once, the last one close to a multiple of the
// round-off-sized one before it. A fit to them moved the guess by about ||X|| (a node beyond the wall) and the step
// was rejected; now these errors are not used, and the next steps are those from the extrapolation, bitwise.
TEST(GuessErrorPredictor, CellAtRestIsNotMovedByRoundOffSizedErrors) {
  auto log = [](const std::string& line) { ADD_FAILURE() << line; };
  Simulation sim = cell_at_rest("recurrence"), plain = cell_at_rest("extrapolation");
  for (int k = 0; k < 2; ++k) {
    sim.advance(log);
    plain.advance(log);
  }
  io::Checkpoint ck = sim.checkpoint();
  const auto X = sim.op().positions();
  const std::size_t n = X.size();
  const double size = norm(X);
  auto roundoff = [&](unsigned seed) {
    auto e = random_vector(n, seed);
    for (std::size_t i = 0; i < n; ++i) e[i] *= 1e-16 * X[i];
    return e;
  };
  std::vector<std::vector<double>> history{scaled(random_vector(n, 601), 1e-8 * size),
                                           scaled(random_vector(n, 602), 1.5e-8 * size), roundoff(603), roundoff(604)};
  auto last = scaled(history.back(), 1e-8 * size);
  const auto extra = scaled(random_vector(n, 605), 1e-10 * size);
  for (std::size_t i = 0; i < n; ++i) last[i] += extra[i];
  history.push_back(last);
  std::vector<double> errors;
  for (const auto& e : history) errors.insert(errors.end(), e.begin(), e.end());
  ck.erase("integrator.guess_errors");
  ck.put_array("integrator.guess_errors", errors);
  Simulation restarted = cell_at_rest("recurrence");
  restarted.restore(ck);
  for (int k = 0; k < 3; ++k) {
    const StepRecord r = restarted.advance(log);
    EXPECT_EQ(r.rejected, 0) << "step " << r.step;
    plain.advance(log);
    if (k < 2) {  // the injected errors are not used
      const auto a = restarted.op().positions(), b = plain.op().positions();
      EXPECT_TRUE(std::ranges::equal(a, b)) << "step " << r.step;
    }
  }
}
