// The coupled operator of §3 (ImmersedBoundaryOperator) with several membranes: the trial velocity does not depend
// on the thread count (membranes are shared among threads), the start-of-step force taken over from an implicit
// step's last trial is the one recomputed from scratch, and a failing membrane is named.
#include <gtest/gtest.h>
#include <omp.h>

#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
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
  ImmersedBoundaryOperator make_operator() {
    std::vector<const ElasticMembrane*> ms;
    for (const auto& m : membranes) ms.push_back(&m);
    return ImmersedBoundaryOperator(fluid, coupler, ms, X0, fluid.initial_state());
  }
};

std::vector<double> shifted(std::span<const double> X, double by) {
  std::vector<double> Y(X.begin(), X.end());
  for (std::size_t i = 0; i < Y.size(); ++i) Y[i] += by * static_cast<double>(i % 7) / 7.0;
  return Y;
}

}  // namespace

TEST(ImmersedBoundaryOperator, TrialVelocityOfManyMembranesIsBitwiseIndependentOfTheThreadCount) {
  Cells s;
  const int saved = omp_get_max_threads();
  std::vector<std::vector<double>> U;
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    auto op = s.make_operator();
    const auto X = shifted(op.positions(), 1e-2);
    std::vector<double> u(op.size());
    op.trial_velocity(X, 0.5, X, 0.1, u);
    U.push_back(u);
  }
  omp_set_num_threads(saved);
  double largest = 0;
  for (double v : U[0]) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 0.0);
  EXPECT_EQ(U[0], U[1]);
  EXPECT_EQ(U[0], U[2]);
}

TEST(ImmersedBoundaryOperator, StartForceTakenOverFromTheLastTrialEqualsTheRecomputedOne) {
  Cells s;
  auto reused = s.make_operator();
  auto recomputed = s.make_operator();
  const auto X1 = shifted(reused.positions(), 1e-2);
  std::vector<double> U(reused.size());
  // An implicit step ends with a trial at X^{n+1}: commit takes S(X^{n+1}) f(X^{n+1}) over from it.
  reused.trial_velocity(X1, 0.5, X1, 0.1, U);
  reused.commit(X1, 0.1);
  // Applied forces (here zero) invalidate the trial's force: commit recomputes it.
  recomputed.trial_velocity(X1, 0.5, X1, 0.1, U);
  recomputed.set_applied_forces(0, std::vector<Vec3>(s.mesh.nodes.size()));
  recomputed.commit(X1, 0.1);
  const auto X2 = shifted(X1, 1e-2);
  std::vector<double> Ua(reused.size()), Ub(reused.size());
  reused.trial_velocity(X2, 0.5, X2, 0.1, Ua);
  recomputed.trial_velocity(X2, 0.5, X2, 0.1, Ub);
  EXPECT_EQ(Ua, Ub);
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
  for (int threads : {1, 2}) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    try {
      op.trial_velocity(X, 0.5, X, 0.1, U);
      ADD_FAILURE() << "inverted membranes were not detected";
    } catch (const SimulationError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("membrane[2] ", 0), 0u) << e.what();
    }
    omp_set_num_threads(saved);
  }
}
