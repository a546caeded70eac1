// The coupled operator of §3 (ImmersedBoundaryOperator) with several membranes: the trial velocity does not depend
// on the thread count (membranes are shared among threads), the start-of-step force is taken over from an implicit
// step's last trial only when that is the force at the committed positions, the prepared fluid step only for the
// committed state and dt, and a failing membrane is named (an inverted element with where it stands).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

// GCC 12's libstdc++ <regex> trips -Wmaybe-uninitialized inside its own automaton code at -O1 (a known false
// positive, GCC bug 105562); the warning is about the library header, not this test.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <regex>
#pragma GCC diagnostic pop

#include "immerse/core/Error.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/simulation/ImmersedBoundaryOperator.hpp"

using namespace immerse;

namespace {

constexpr Boundary P = Boundary::Periodic;
constexpr int kMembranes = 5;

// Five unit-radius spheres (icosahedral level 1) at rest, in a 16^3 periodic box of side 8, and their positions:
// each stretched a little differently, so that every membrane exerts its own force.
struct Cells {
  Grid grid{{16, 16, 16}, {8.0, 8.0, 8.0}, {P, P, P}};
  NavierStokesSolver fluid{grid, FluidParams{}, FftPlanning::Estimate};
  IBCoupler coupler{grid};
  Mesh mesh = icosahedral_sphere(1);
  std::vector<ElasticMembrane> membranes;
  std::vector<std::vector<Vec3>> X0;

  Cells() {
    for (int m = 0; m < kMembranes; ++m) {
      const Vec3 centre{1.5 + 1.2 * m, 2.0 + 0.9 * m, 4.0};
      std::vector<Vec3> ref, x;
      for (const Vec3& p : mesh.nodes) {
        ref.push_back(centre + 0.5 * p);
        x.push_back(centre + Vec3{0.5 * (1 + 0.05 * m) * p.x, 0.5 * p.y, 0.5 / (1 + 0.05 * m) * p.z});
      }
      membranes.emplace_back(mesh, ref, NeoHookean{1.0}, Bending{}, ForceMethod::Contour);
      X0.push_back(x);
    }
  }
  std::vector<const ElasticMembrane*> pointers() const {
    std::vector<const ElasticMembrane*> ms;
    for (const auto& m : membranes) ms.push_back(&m);
    return ms;
  }
  ImmersedBoundaryOperator make_operator() {
    return ImmersedBoundaryOperator(fluid, coupler, pointers(), X0, fluid.initial_state());
  }
  /// A new operator at the committed positions of `op` with the fluid state `f` (nothing prepared yet).
  ImmersedBoundaryOperator make_operator(const ImmersedBoundaryOperator& op, const FluidState& f) {
    std::vector<std::vector<Vec3>> X;
    for (std::size_t m = 0; m < op.num_membranes(); ++m) X.push_back(op.membrane_positions(m));
    return ImmersedBoundaryOperator(fluid, coupler, pointers(), X, f);
  }
};

std::vector<double> shifted(std::span<const double> X, double by) {
  std::vector<double> Y(X.begin(), X.end());
  for (std::size_t i = 0; i < Y.size(); ++i) Y[i] += by * static_cast<double>(i % 7) / 7.0;
  return Y;
}

/// Sets the OpenMP thread count for its lifetime.
class Threads {
 public:
  explicit Threads(int n) : saved_(omp_get_max_threads()) { omp_set_num_threads(n); }
  ~Threads() { omp_set_num_threads(saved_); }
  Threads(const Threads&) = delete;
  Threads& operator=(const Threads&) = delete;

 private:
  int saved_;
};

}  // namespace

TEST(ImmersedBoundaryOperator, TrialVelocityOfManyMembranesIsBitwiseIndependentOfTheThreadCount) {
  Cells s;
  std::vector<std::vector<double>> U;
  for (int threads : {1, 2, 3}) {  // 3: fewer than 2 membranes per thread, each membrane with OpenMP inside
    const Threads t(threads);
    auto op = s.make_operator();
    const auto X = shifted(op.positions(), 1e-2);
    std::vector<double> u(op.size());
    op.trial_velocity(X, 0.5, X, 0.1, u);
    U.push_back(u);
  }
  double largest = 0;
  for (double v : U[0]) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 0.0);
  EXPECT_EQ(U[0], U[1]);
  EXPECT_EQ(U[0], U[2]);
}

TEST(ImmersedBoundaryOperator, MembraneOffsetsSplitTheUnknownsByMembrane) {
  Cells s;
  const auto op = s.make_operator();
  const auto offsets = op.membrane_offsets();
  ASSERT_EQ(offsets.size(), static_cast<std::size_t>(kMembranes) + 1);
  for (int m = 0; m <= kMembranes; ++m) EXPECT_EQ(offsets[m], 3 * s.mesh.nodes.size() * static_cast<std::size_t>(m));
  EXPECT_EQ(offsets.back(), op.size());
}

// An implicit step's last trial is driven and interpolated at X^{n+1}: commit takes its J(X^{n+1}) u^{n+1} over
// (no interpolation), bitwise equal to interpolating the committed velocity; at other positions it interpolates.
TEST(ImmersedBoundaryOperator, NodeVelocityIsTakenOverOnlyFromATrialAtTheCommittedPositions) {
  Cells s;
  std::vector<double> X0v;
  {
    const auto op = s.make_operator();
    X0v.assign(op.positions().begin(), op.positions().end());
  }
  const auto X1 = shifted(X0v, 1e-2), X1b = shifted(X0v, 2e-2);
  std::vector<double> U(X1.size()), expected(X1.size());
  for (const auto* at : {&X1, &X1b}) {
    auto op = s.make_operator();
    op.trial_velocity(X1, 0.5, X1, 0.1, U);
    const double interpolating = op.timings().interpolate;
    op.commit(*at, 0.1);
    if (at == &X1)
      EXPECT_EQ(op.timings().interpolate, interpolating);
    else
      EXPECT_GT(op.timings().interpolate, interpolating);
    const std::vector<double> taken(op.node_velocity().begin(), op.node_velocity().end());
    op.committed_velocity(*at, expected);
    EXPECT_EQ(taken, expected);
  }
}

// The midpoint rule's velocity J(Xi) (u^n + u^{n+1}) / 2, one interpolation of the mean field, is the mean of the two
// interpolations (J is linear in u) to round-off, from a committed state that is not at rest, for one fluid step.
TEST(ImmersedBoundaryOperator, TrialMeanVelocityIsTheMeanOfTheCommittedAndTrialVelocities) {
  Cells s;
  auto op = s.make_operator();
  const std::vector<double> X0v(op.positions().begin(), op.positions().end());
  const auto X1 = shifted(X0v, 1e-2), X2 = shifted(X1, 1e-2), X3 = shifted(X2, 1e-2);
  std::vector<double> U(op.size()), Un(op.size()), Um(op.size());
  op.trial_velocity(X1, 1.0, X1, 0.1, U);
  op.commit(X1, 0.1);
  op.trial_velocity(X2, 1.0, X3, 0.1, U);
  op.committed_velocity(X3, Un);
  const std::size_t solves = op.fluid_solves();
  op.trial_mean_velocity(X2, X3, 0.1, Um);
  EXPECT_EQ(op.fluid_solves(), solves + 1);
  EXPECT_TRUE(op.trial_matches(X2));
  double largest = 0, error = 0, change = 0;
  for (std::size_t i = 0; i < U.size(); ++i) {
    largest = std::max(largest, std::abs(U[i]));
    error = std::max(error, std::abs(Um[i] - 0.5 * (Un[i] + U[i])));
    change = std::max(change, std::abs(U[i] - Un[i]));
  }
  EXPECT_GT(change, 0.1 * largest);
  EXPECT_LT(error, 1e-14 * largest);
}

// The start force S(X^n) f(X^n) of the next step, seen through the trial velocity at X2 (theta = 1/2 mixes it in).
// An implicit step ends with a trial at X^{n+1}; commit takes its S(X^{n+1}) f(X^{n+1}) over. Applied forces set
// before or after the commit, and a commit at other positions than the last trial's, must not reuse it.
TEST(ImmersedBoundaryOperator, StartForceIsTakenOverOnlyWhenItIsTheOneAtTheCommittedPositions) {
  Cells s;
  std::vector<Vec3> applied(s.mesh.nodes.size());
  for (std::size_t i = 0; i < applied.size(); ++i) applied[i] = {1e-2 * double(i % 3), -2e-2, 1e-2 * double(i % 5)};
  std::vector<double> X0v;
  {
    const auto op = s.make_operator();
    X0v.assign(op.positions().begin(), op.positions().end());
  }
  const auto X1 = shifted(X0v, 1e-2), X1b = shifted(X0v, 2e-2), X2 = shifted(X1, 1e-2);
  std::vector<double> U(3 * s.mesh.nodes.size() * kMembranes);
  auto next_velocity = [&](ImmersedBoundaryOperator& op) {
    std::vector<double> u(op.size());
    op.trial_velocity(X2, 0.5, X2, 0.1, u);
    return u;
  };
  // Applied forces set before the commit (no takeover) or after it (takeover, then invalidated): the same state.
  auto before = s.make_operator(), after = s.make_operator();
  before.trial_velocity(X1, 0.5, X1, 0.1, U);
  before.set_applied_forces(1, applied);
  before.commit(X1, 0.1);
  after.trial_velocity(X1, 0.5, X1, 0.1, U);
  after.commit(X1, 0.1);
  after.set_applied_forces(1, applied);
  const auto u_before = next_velocity(before);
  EXPECT_EQ(u_before, next_velocity(after));
  // Without the applied forces the taken-over start force differs from it (the comparison above can fail).
  auto plain = s.make_operator();
  plain.trial_velocity(X1, 0.5, X1, 0.1, U);
  plain.commit(X1, 0.1);
  EXPECT_NE(u_before, next_velocity(plain));
  // A commit at X1b after a trial at X1 recomputes the start force at X1b, as an invalidated one is.
  auto other = s.make_operator(), invalidated = s.make_operator();
  other.trial_velocity(X1, 0.5, X1, 0.1, U);
  other.commit(X1b, 0.1);
  invalidated.trial_velocity(X1, 0.5, X1, 0.1, U);
  invalidated.set_applied_forces(0, std::vector<Vec3>(s.mesh.nodes.size()));
  invalidated.commit(X1b, 0.1);
  EXPECT_EQ(next_velocity(other), next_velocity(invalidated));
  // ... and not the trial's: a commit at X1 (takeover) with the same fluid state gives another velocity.
  EXPECT_NE(next_velocity(other), next_velocity(plain));
}

// The force-independent part of the fluid step is prepared once and shared by the trials with the committed state
// and dt it was made for. Each trial of an operator that has prepared before (for the same state and dt, for another
// dt, for the state before the last commit) is bitwise the trial of an operator freshly made in the same state; the
// inequalities show that a stale prepared step (another dt, the state before the commit) would have been seen.
TEST(ImmersedBoundaryOperator, TrialsReuseThePreparedFluidStepOnlyForTheCommittedStateAndDt) {
  Cells s;
  auto op = s.make_operator();
  const std::vector<double> X0v(op.positions().begin(), op.positions().end());
  const auto X1 = shifted(X0v, 1e-2), X1b = shifted(X0v, 2e-2), X2 = shifted(X1, 1e-2), X2b = shifted(X1, 2e-2);
  const auto trial = [](ImmersedBoundaryOperator& o, const std::vector<double>& X, double dt) {
    std::vector<double> u(o.size());
    o.trial_velocity(X, 0.5, X, dt, u);
    return u;
  };
  // The trial of a new operator at the committed positions of `like`, from the fluid state f (default: like's).
  const auto fresh_trial = [&](const ImmersedBoundaryOperator& like, const std::vector<double>& X, double dt,
                               const FluidState* f = nullptr) {
    auto o = s.make_operator(like, f ? *f : like.fluid_state());
    return trial(o, X, dt);
  };
  // Step 1 (forward Euler in the fluid): a second trial with the same dt, then trials with another dt and back.
  trial(op, X1, 0.1);
  const auto u1b = trial(op, X1b, 0.1);
  EXPECT_EQ(u1b, fresh_trial(op, X1b, 0.1));
  const auto u1b_half = trial(op, X1b, 0.05);
  EXPECT_EQ(u1b_half, fresh_trial(op, X1b, 0.05));
  EXPECT_NE(u1b_half, u1b);
  EXPECT_EQ(trial(op, X1b, 0.1), u1b);
  // Step 2 (Adams–Bashforth): committed at X1 after a trial there with dt = 0.1, then trials with that same dt.
  const FluidState start = op.fluid_state();
  trial(op, X1, 0.1);
  op.commit(X1, 0.1);
  ASSERT_EQ(op.fluid_state().step, 1);
  const auto u2 = trial(op, X2, 0.1);
  EXPECT_EQ(u2, fresh_trial(op, X2, 0.1));
  EXPECT_NE(u2, fresh_trial(op, X2, 0.1, &start));  // what the step prepared before the commit would give
  const auto u2b = trial(op, X2b, 0.1);
  EXPECT_EQ(u2b, fresh_trial(op, X2b, 0.1));
  // Step 3: committed at X2b after the trial there, then trials with a new dt.
  op.commit(X2b, 0.1);
  ASSERT_EQ(op.fluid_state().step, 2);
  EXPECT_EQ(trial(op, X1b, 0.08), fresh_trial(op, X1b, 0.08));
  EXPECT_EQ(trial(op, X2, 0.08), fresh_trial(op, X2, 0.08));
}

// An element of membrane 2 folded over (a mid-side node mirrored through the membrane's centre): the message names it
// with its area against its stress-free area, the least of the membrane, and the nearest node of another membrane
// (the minimum image in the periodic box, which has no wall to name).
TEST(ImmersedBoundaryOperator, AnInvertedElementIsNamedWithWhereItStands) {
  Cells s;
  auto op = s.make_operator();
  std::vector<double> X(op.positions().begin(), op.positions().end());
  const std::size_t per = s.mesh.nodes.size();
  const auto at = [&](std::size_t m, std::size_t i) {
    const std::size_t k = 3 * (m * per + i);
    return Vec3{X[k], X[k + 1], X[k + 2]};
  };
  const Vec3 centre{1.5 + 1.2 * 2, 2.0 + 0.9 * 2, 4.0};
  const std::size_t moved = static_cast<std::size_t>(s.mesh.elements[0][3]);
  for (int a = 0; a < 3; ++a) X[3 * (2 * per + moved) + a] = 2 * centre[a] - X[3 * (2 * per + moved) + a];
  std::vector<double> U(op.size());
  try {
    op.trial_velocity(X, 0.5, X, 0.1, U);
    ADD_FAILURE() << "the inverted element was not detected";
  } catch (const SimulationError& e) {
    const std::string what = e.what();
    std::smatch m;
    ASSERT_TRUE(std::regex_match(what, m,
                                 std::regex(R"(membrane\[2\] element (\d+): Jacobian <= 0 or not finite \(element )"
                                            R"(inverted or degenerate\); area ratio ([0-9.e+-]+) \(least of the )"
                                            R"(membrane ([0-9.e+-]+), element (\d+)\), ([0-9.e+-]+) m from )"
                                            R"(membrane\[(\d+)\])")))
        << what;
    const std::size_t element = std::stoul(m[1]);
    ASSERT_LT(element, s.mesh.num_elements());
    EXPECT_TRUE(std::ranges::find(s.mesh.elements[element], static_cast<int>(moved)) != s.mesh.elements[element].end())
        << "element " << element << " does not hold the node that was moved";
    std::vector<Vec3> X2;
    for (std::size_t i = 0; i < per; ++i) X2.push_back(at(2, i));
    const auto reference = s.membranes[2].reference_element_areas();
    const double ratio = element_areas(s.mesh, X2)[element] / reference[element];
    EXPECT_NEAR(std::stod(m[2]), ratio, 5e-3 * ratio);
    const LeastAreaRatio least = least_area_ratio(s.mesh, X2, reference);
    EXPECT_NEAR(std::stod(m[3]), least.ratio, 5e-3 * least.ratio);
    EXPECT_EQ(std::stoul(m[4]), least.element);
    double nearest = 1e300;
    std::size_t which = 0;
    for (std::size_t o = 0; o < std::size_t(kMembranes); ++o)
      for (std::size_t i = 0; i < per && o != 2; ++i)
        for (const int n : s.mesh.elements[element]) {
          Vec3 d = at(o, i) - X2[static_cast<std::size_t>(n)];
          for (int a = 0; a < 3; ++a) d[a] -= 8.0 * std::nearbyint(d[a] / 8.0);
          if (norm(d) < nearest) nearest = norm(d), which = o;
        }
    EXPECT_NEAR(std::stod(m[5]), nearest, 5e-3 * nearest);
    EXPECT_EQ(std::stoul(m[6]), which);
  }
}

TEST(ImmersedBoundaryOperator, TheLowestNumberedFailingMembraneIsNamed) {
  Cells s;
  auto op = s.make_operator();
  std::vector<double> X(op.positions().begin(), op.positions().end());
  const std::size_t per = s.mesh.nodes.size();
  for (int m : {4, 2})  // collapse membranes 4 and 2 onto one node: their elements degenerate
    for (std::size_t i = 0; i < per; ++i)
      for (int a = 0; a < 3; ++a) X[3 * (m * per + i) + a] = X[3 * m * per + a];
  std::vector<double> U(op.size());
  for (int threads : {1, 2, 3}) {
    const Threads t(threads);
    try {
      op.trial_velocity(X, 0.5, X, 0.1, U);
      ADD_FAILURE() << "inverted membranes were not detected";
    } catch (const SimulationError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("membrane[2] ", 0), 0u) << e.what();
    }
  }
}
